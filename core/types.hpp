// Basic numeric types shared by the whole engine.
// All quantities are SI (m, kg, s, N, Pa, J) unless a name says otherwise.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <Eigen/LU>        // determinant, inverse
#include <cstdint>

namespace fl {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec3i = Eigen::Vector3i;

constexpr double kPi = 3.14159265358979323846;

}  // namespace fl
