/// Tests of the finite-difference generalizer (thesis eq. 3-17 ... 3-22).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "jackal_aic/aic/generalizer.hpp"

using jackal_aic::aic::Generalizer;

namespace
{
constexpr double kExactTol = 1e-9;  // relative, for closed-form coefficients
constexpr double kDerivTol = 1e-6;  // signal units per s^i
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

TEST(Generalizer, QRowsMatchThesisEq322)
{
  // Expansion of the recursion: row i = [1/h^i, -1/h^i, -1/h^(i-1), ..., -1/h, 0, ...].
  for (double h : { 0.02, 0.001, 0.5 })
  {
    for (int p = 1; p <= 5; ++p)
    {
      const Eigen::MatrixXd q = Generalizer::buildQ(p, h);
      ASSERT_EQ(q.rows(), p + 1);
      EXPECT_EQ(q(0, 0), 1.0);
      EXPECT_TRUE(q.row(0).tail(p).isZero());
      for (int i = 1; i <= p; ++i)
      {
        EXPECT_NEAR(q(i, 0), std::pow(h, -i), kExactTol * std::pow(h, -i));
        for (int j = 1; j <= p; ++j)
        {
          const double expected = j <= i ? -std::pow(h, -(i - j + 1)) : 0.0;
          EXPECT_NEAR(q(i, j), expected, kExactTol * std::abs(expected) + 1e-300) << "p=" << p << " i=" << i;
        }
      }
    }
  }
  // Thesis-style explicit rows for p = 2: y'' = (y_k - y_{k-1}) / h^2 - y'_{k-1} / h.
  const Eigen::MatrixXd q = Generalizer::buildQ(2, 0.1);
  EXPECT_NEAR(q(2, 0), 100.0, 1e-9);
  EXPECT_NEAR(q(2, 1), -100.0, 1e-9);
  EXPECT_NEAR(q(2, 2), -10.0, 1e-9);
  EXPECT_THROW(Generalizer::buildQ(0, 0.1), std::invalid_argument);
  EXPECT_THROW(Generalizer::buildQ(2, 0.0), std::invalid_argument);
}

TEST(Generalizer, RecoversRampAndParabola)
{
  constexpr double kH = 0.01;  // s
  Generalizer g(2, 3);
  Eigen::Vector2d y;
  for (int k = 0; k < 20; ++k)
  {
    const double t = k * kH;
    y << 2.0 + 3.0 * t, 1.0 - 0.5 * t + 4.0 * t * t;  // ramp, parabola
    const auto s = g.update(y, kH);
    EXPECT_TRUE(s == Generalizer::Status::kOk || s == Generalizer::Status::kFirstSample);
  }
  const double t = 19 * kH;
  EXPECT_NEAR(g.yTilde()(0, 0), 2.0 + 3.0 * t, kDerivTol);
  EXPECT_NEAR(g.yTilde()(0, 1), 3.0, kDerivTol);
  EXPECT_NEAR(g.yTilde()(0, 2), 0.0, kDerivTol);
  // Backward difference of a parabola: slope at the midpoint of the last interval.
  EXPECT_NEAR(g.yTilde()(1, 1), -0.5 + 8.0 * (t - kH / 2), kDerivTol);
  EXPECT_NEAR(g.yTilde()(1, 2), 8.0, 1e-4);
  EXPECT_NEAR(g.yTilde()(1, 3), 0.0, 1e-3);
}

TEST(Generalizer, BadSamplesKeepState)
{
  Generalizer g(1, 2);
  Eigen::VectorXd y(1);
  y << 1.0;
  EXPECT_EQ(g.update(y, 0.0), Generalizer::Status::kFirstSample);  // h ignored for the first sample
  y << 2.0;
  EXPECT_EQ(g.update(y, 0.1), Generalizer::Status::kOk);
  const Eigen::MatrixXd before = g.yTilde();
  y << 5.0;
  for (double bad : { 0.0, -0.1, kNaN, std::numeric_limits<double>::infinity(), 1e-300 })
  {
    EXPECT_EQ(g.update(y, bad), Generalizer::Status::kBadInterval) << bad;
    EXPECT_EQ(g.yTilde(), before);
  }
  y << kNaN;
  EXPECT_EQ(g.update(y, 0.1), Generalizer::Status::kNonFiniteValue);
  Eigen::VectorXd wrong(2);
  wrong << 1.0, 2.0;
  EXPECT_EQ(g.update(wrong, 0.1), Generalizer::Status::kSizeMismatch);
  EXPECT_EQ(g.yTilde(), before);
  EXPECT_EQ(g.rejectedCount(), 7u);
  EXPECT_EQ(g.acceptedCount(), 2u);
  EXPECT_TRUE(g.yTilde().allFinite());
  g.reset();
  EXPECT_FALSE(g.initialized());
  EXPECT_TRUE(g.yTilde().isZero());
}

TEST(Generalizer, RejectsBadConstruction)
{
  EXPECT_THROW(Generalizer(0, 3), std::invalid_argument);
  EXPECT_THROW(Generalizer(5, 0), std::invalid_argument);
  EXPECT_THROW(Generalizer(5, 6), std::invalid_argument);
}
