// Materials and the pair parameters mixed from them at setup.
// The hot loop only indexes the PairTable by (material_i, material_j); R* and m* are formed from the
// two particles' radii and inverse masses (two divisions), which is cheaper than a per-pair table.
#pragma once

#include <string>
#include <vector>

namespace fl {

struct Material {
  std::string name = "glass";
  double youngModulus = 70.0e9;   // E [Pa]
  double poissonRatio = 0.22;     // nu [-]
  double density = 2570.0;        // rho [kg/m^3]
  double friction = 0.235;        // mu, interparticle Coulomb coefficient [-]

  double shearModulus() const { return youngModulus / (2.0 * (1.0 + poissonRatio)); }  // G [Pa]
  static Material fromShearModulus(std::string name, double G, double nu, double rho, double mu) {
    return Material{std::move(name), 2.0 * G * (1.0 + nu), nu, rho, mu};
  }
  // The paper's Table 1 glass beads: rho 2570 kg/m^3, mu 0.235, nu 0.22, G 28.688 GPa.
  static Material paperGlass() { return fromShearModulus("glass", 28.688e9, 0.22, 2570.0, 0.235); }
};

// Mixed parameters for one material pair.
struct PairParams {
  double effYoung = 0.0;   // E*, 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2 [Pa]
  double effShear = 0.0;   // G*, 1/G* = (2-nu1)/G1 + (2-nu2)/G2 [Pa]
  double friction = 0.0;   // mu [-]
  double dampingRatio = 0.0;  // -beta: Tsuji form, 0 = no contact damping, from restitution e [-]
};

// The smallest restitution the contact damping accepts. Below it the Tsuji damping ratio grows without bound
// (e = 0.01 needs beta = 4.8, about 4.4 times critical damping; e = 1e-4 needs 50), the explicit step is no
// longer stable with it, and finding beta took seconds to minutes (a fuzzed checkpoint with e near 1e-300 ran
// the search for longer than the fuzzer's 15 s limit).
constexpr double kMinRestitution = 0.01;

// Damping ratio beta of the Tsuji et al. (1992) Hertzian viscoelastic damping that gives the
// restitution coefficient e in [kMinRestitution, 1] exactly (speed-independent for Hertz; found numerically).
double dampingRatioFromRestitution(double restitution);

class PairTable {
 public:
  PairTable() = default;
  PairTable(const std::vector<Material>& materials, double restitution);

  const PairParams& operator()(int a, int b) const { return m_params[a * m_count + b]; }
  int materialCount() const { return m_count; }
  // Friction can change during a run (the paper compresses with mu_c, then shears with mu).
  void setFriction(double mu);
  void setRestitution(double restitution);

 private:
  int m_count = 0;
  std::vector<PairParams> m_params;
};

}  // namespace fl
