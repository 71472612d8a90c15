/// Tests of the skid-steer generative model G, R, K (thesis eq. 3-1 ... 3-4).
#include <gtest/gtest.h>

#include <limits>

#include "jackal_aic/aic/skid_steer_model.hpp"

using namespace jackal_aic;

namespace
{
constexpr double kTol = 1e-12;  // rad/s, m/s
constexpr double kR = 0.098;    // m
constexpr double kB = 0.5621;   // m
}  // namespace

TEST(SkidSteerModel, Matrices)
{
  const aic::SkidSteerModel m(kR, 1.0, kB);
  EXPECT_NEAR(m.G()(0, 0), kR / 2, kTol);
  EXPECT_NEAR(m.G()(2, 1), kR / kB, kTol);
  EXPECT_NEAR(m.G()(2, 0), -kR / kB, kTol);
  // Wheel rows: omega_L = (x_dot - theta_dot b/2) / r, omega_R = (x_dot + theta_dot b/2) / r.
  EXPECT_NEAR(m.R()(base::kOmegaLeft, 0), 1.0 / kR, kTol);
  EXPECT_NEAR(m.R()(base::kOmegaLeft, 2), -kB / (2 * kR), kTol);
  EXPECT_NEAR(m.R()(base::kOmegaRight, 2), kB / (2 * kR), kTol);
  EXPECT_NEAR(m.R()(base::kOmegaRight, 1), 0.0, kTol);
  EXPECT_EQ(m.R()(base::kGyroZ, 2), 1.0);
  EXPECT_TRUE(m.R().bottomRows(2).isZero());
  EXPECT_NEAR(m.K()(0, base::kGyroZ), -kR / kB, kTol);
  EXPECT_NEAR(m.K()(1, base::kGyroZ), kR / kB, kTol);
  EXPECT_EQ(m.K()(0, base::kOmegaLeft), 1.0);
  EXPECT_EQ(m.K()(1, base::kOmegaRight), 1.0);
}

TEST(SkidSteerModel, RoundTrip)
{
  const aic::SkidSteerModel m(kR, 0.9, kB);
  const base::Vector2 w(3.0, -1.5);
  EXPECT_TRUE(m.wheelsFromTwist(m.twistFromWheels(w)).isApprox(w, kTol));
  // K matches the derivative of R G a with respect to a for the gyro and wheel rows.
  const Eigen::Matrix<double, 5, 2> dyda = m.R() * m.G();
  EXPECT_TRUE(dyda.topRows(3).transpose().isApprox(m.K().leftCols(3), kTol));
}

TEST(SkidSteerModel, RejectsBadGeometry)
{
  EXPECT_THROW(aic::SkidSteerModel(0.0, 1.0, kB), std::invalid_argument);
  EXPECT_THROW(aic::SkidSteerModel(kR, -1.0, kB), std::invalid_argument);
  EXPECT_THROW(aic::SkidSteerModel(kR, 1.0, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}
