/**
 * \file skid_steer_model.cpp
 * \brief G, R, K of the skid-steer generative model (thesis eq. 3-1 ... 3-4;
 *        doc/active_inference.md, 'Generative model of the sensory data').
 */
#include "jackal_aic/aic/skid_steer_model.hpp"

#include <Eigen/QR>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jackal_aic
{
namespace aic
{
namespace
{
void requirePositive(const char* name, double v)
{
  if (!(std::isfinite(v) && v > 0.0))
  {
    throw std::invalid_argument(std::string("SkidSteerModel: ") + name + " = " + std::to_string(v) +
                                " (allowed: > 0 and finite)");
  }
}
}  // namespace

SkidSteerModel::SkidSteerModel(double wheel_radius, double slip_factor, double wheel_separation)
{
  requirePositive("wheel_radius", wheel_radius);
  requirePositive("slip_factor", slip_factor);
  requirePositive("wheel_separation", wheel_separation);
  const double ra = wheel_radius * slip_factor;
  const double b = wheel_separation;
  ra_ = ra;
  b_ = b;

  // Thesis eq. 3-1: extended differential drive (Mandow et al. 2007).
  G_ << 0.5 * ra, 0.5 * ra,  //
      0.0, 0.0,              //
      -ra / b, ra / b;

  // Wheel rows of R: the Moore-Penrose pseudo-inverse of G (thesis eq. 3-3), computed by Eigen.
  // Decomposed at dynamic size: Eigen 3.3 (Ubuntu 20.04: 3.3.7, Debian 11: 3.3.9) gives the
  // pseudo-inverse of a fixed-size 3x2 decomposition the wrong compile-time shape (3x2, not
  // 2x3) and refuses the assignment; 3.4 does not. Once, in the constructor.
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod{ Eigen::MatrixXd(G_) };
  G_pinv_ = cod.pseudoInverse();

  R_.setZero();
  R_(base::kGyroZ, 2) = 1.0;  // gyro z measures theta_dot
  R_.row(base::kOmegaLeft) = G_pinv_.row(0);
  R_.row(base::kOmegaRight) = G_pinv_.row(1);
  // Accelerometer rows stay zero (thesis model).

  // Thesis eq. 3-4: K = dy/da, one row per action (omega_L, omega_R).
  K_.setZero();
  K_(0, base::kGyroZ) = -ra / b;
  K_(0, base::kOmegaLeft) = 1.0;
  K_(1, base::kGyroZ) = ra / b;
  K_(1, base::kOmegaRight) = 1.0;
}

bool SkidSteerModel::setWheelSeparation(double b)
{
  if (!(std::isfinite(b) && b > 0.0))
  {
    return false;
  }
  const double ra = ra_;
  b_ = b;
  G_(2, 0) = -ra / b;
  G_(2, 1) = ra / b;
  // pinv(G) = (G^T G)^-1 G^T: G has full column rank, so its pseudo-inverse is its left inverse.
  G_pinv_ << 1.0 / ra, 0.0, -0.5 * b / ra,  //
      1.0 / ra, 0.0, 0.5 * b / ra;
  R_.row(base::kOmegaLeft) = G_pinv_.row(0);
  R_.row(base::kOmegaRight) = G_pinv_.row(1);
  K_(0, base::kGyroZ) = -ra / b;
  K_(1, base::kGyroZ) = ra / b;
  return true;
}

base::Vector2 SkidSteerModel::wheelsFromTwist(const base::Vector3& mu) const
{
  return G_pinv_ * mu;
}

}  // namespace aic
}  // namespace jackal_aic
