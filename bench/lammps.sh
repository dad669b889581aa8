# What the LAMMPS comparisons share (sourced by lammps_side_by_side.sh and lammps_scaling.sh): Debian's
# package, the input for bench_dense's scene and one timed run. Needs `die` from the sourcing script.

# ensure_lammps: installs Debian's lammps and Open MPI if missing (idempotent; never yade or paraview, which
# remove libvtk9-dev) and prints the package's version
ensure_lammps() {
  if ! dpkg -s lammps >/dev/null 2>&1 || ! command -v lmp >/dev/null 2>&1; then
    local sudo=""
    [[ $(id -u) -ne 0 ]] && sudo="sudo"
    echo "installing Debian's lammps ..." >&2
    $sudo apt-get update -qq >&2  # stdout carries the version only
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends lammps openmpi-bin >/dev/null
  fi
  command -v mpirun >/dev/null || die "mpirun not found (Debian package openmpi-bin)"
  dpkg -s lammps | sed -n 's/^Version: //p'
}

# export_field LINE NAME: a field of bench_dense's "export:" line (E, nu, mu, skin, dt, p0, Z0, N ...)
export_field() { sed -n "s/.* $2=\([^ ]*\).*/\1/p" <<<"$1"; }

# write_lammps_input FILE DATA EXPORT_LINE STEPS: the LAMMPS input for the scene bench_dense exported to DATA,
# the same physics as FabricLab's benchmark: Hertz with E* from E and nu (hertz/material), Mindlin no-slip
# tangential spring k_t = 8 G* a (tangential mindlin NULL), Coulomb mu, no damping (eta_n0 = 0,
# x_gamma_t = 0), no rolling or twisting, newton on, fix nve/sphere, same dt and skin; prints p and
# Z = 2C/N at step 0 (STEP0 line) and after STEPS steps (END line)
write_lammps_input() {
  local file="$1" data="$2" line="$3" steps="$4"
  local E nu mu skin dt
  E="$(export_field "$line" E)"; nu="$(export_field "$line" nu)"; mu="$(export_field "$line" mu)"
  skin="$(export_field "$line" skin)"; dt="$(export_field "$line" dt)"
  cat >"$file" <<EOF
# FabricLab benchmark scene: Hertz-Mindlin glass beads, no damping, dt = $dt s
units           si
atom_style      sphere
boundary        p p p
newton          on
comm_modify     vel yes
read_data       $data
neighbor        $skin bin
neigh_modify    delay 0 every 1 check yes
# hertz/material E eta_n0 nu: eta_n0 = 0 -> no normal damping; mindlin NULL -> k_t = 8 G* a from E, nu;
# x_gamma_t = 0 -> no tangential damping; Coulomb mu
pair_style      granular
pair_coeff      * * hertz/material $E 0.0 $nu tangential mindlin NULL 0.0 $mu damping viscoelastic
fix             integrate all nve/sphere
timestep        $dt
compute         zc all contact/atom
compute         zsum all reduce sum c_zc
compute         pv all pressure NULL virial
variable        Z equal c_zsum/atoms
thermo_style    custom step c_pv v_Z
thermo_modify   format float %.10g
run             0
print           "STEP0 p=\$(c_pv:%.12g) Z=\$(v_Z:%.12g)"
run             $steps
print           "END p=\$(c_pv:%.12g) Z=\$(v_Z:%.12g)"
EOF
}

# lammps_rate INPUT RANKS N STEPS LOG: particle-steps/s of one run from its "Loop time" (the run only, no
# setup); rank r bound to core r (Open MPI's default for 2 ranks or fewer, made explicit)
lammps_rate() {
  local input="$1" ranks="$2" n="$3" steps="$4" log="$5" loop
  mpirun --allow-run-as-root --bind-to core -np "$ranks" lmp -in "$input" -log none -screen "$log" \
    >/dev/null 2>&1 || { cat "$log" >&2; die "LAMMPS failed on $ranks rank(s)"; }
  loop="$(awk '/^Loop time of/ {t=$4} END {print t}' "$log")"
  awk -v n="$n" -v s="$steps" -v t="$loop" 'BEGIN {printf "%.6e\n", n * s / t}'
}

# check_same_scene FL_P FL_Z LMP_P LMP_Z: fails when p or Z differ by more than 1 % at step 0
check_same_scene() {
  awk -v a="$1" -v c="$2" -v b="$3" -v d="$4" 'BEGIN {
    dp = (a - b) / b; if (dp < 0) dp = -dp; dz = (c - d) / d; if (dz < 0) dz = -dz;
    printf "  relative difference: p %.2e, Z %.2e\n", dp, dz; exit !(dp <= 0.01 && dz <= 0.01) }' ||
    die "FabricLab and LAMMPS disagree by more than 1 % at step 0: not the same scene"
}
