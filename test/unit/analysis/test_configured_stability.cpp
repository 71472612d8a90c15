/**
 * \file test_configured_stability.cpp
 * \brief The stability check at load (include/jackal_aic/analysis/configured_stability.hpp) on the
 *        embedding-order examples of doc/tuning.md, 'Embedding order and the variance lists'.
 */
#include <gtest/gtest.h>

#include <string>

#include "jackal_aic/analysis/configured_stability.hpp"
#include "jackal_aic/analysis/state_space.hpp"

using namespace jackal_aic;

namespace
{
/// config/thesis_equivalent.yaml's controller keys: table C-1 with var_y^(1) = 1e5, 50 / 50 Hz, Euler.
params::AicParams thesisEquivalent()
{
  params::AicParams p;
  p.belief_rate = 50.0;
  p.action_rate = 50.0;
  p.integrator = params::Integrator::kEuler;
  p.tau = 0.03;
  p.k_mu = 0.01;
  p.k_a = 8.0;
  p.embedding_order = 3;
  p.var_mu = { 1.5, 2.0, 4.0, 8.0 };
  p.var_y = { 2.0, 1.0e5, 1.0e5, 1.0e5 };
  return p;
}

/// Order 4 on top of thesisEquivalent() with the given var_y of order 4.
params::AicParams orderFour(double var_y4)
{
  params::AicParams p = thesisEquivalent();
  p.embedding_order = 4;
  p.var_mu = { 1.5, 2.0, 4.0, 8.0, 16.0 };
  p.var_y = { 2.0, 1.0e5, 1.0e5, 1.0e5, var_y4 };
  return p;
}
}  // namespace

TEST(ConfiguredStability, ThesisEquivalentIsStable)
{
  const analysis::ConfiguredStability s = analysis::checkConfiguredStability(thesisEquivalent());
  ASSERT_TRUE(s.analysed) << s.reason;
  EXPECT_TRUE(s.stable);
  EXPECT_GT(s.spectral_radius, 0.9);
  EXPECT_LT(s.spectral_radius, 1.0);
  EXPECT_EQ(analysis::stabilityWarning(thesisEquivalent()), "");
}

TEST(ConfiguredStability, OrderFourWithTheThesisVarianceWarns)
{
  // doc/tuning.md: var_y [2, 1e5, 1e5, 1e5, 1e5] has a spectral radius of 13.5 whatever var_mu holds.
  const params::AicParams p = orderFour(1.0e5);
  const analysis::ConfiguredStability s = analysis::checkConfiguredStability(p);
  ASSERT_TRUE(s.analysed) << s.reason;
  EXPECT_FALSE(s.stable);
  EXPECT_NEAR(s.spectral_radius, 13.5, 0.1);
  EXPECT_DOUBLE_EQ(s.spectral_radius, analysis::ClosedLoopModel(p).spectralRadius());  // aic_analyze's figure
  const std::string w = analysis::stabilityWarning(p);
  EXPECT_NE(w.find("spectral radius 13."), std::string::npos) << w;
  EXPECT_NE(w.find("belief_rate 50 Hz, action_rate 50 Hz, integrator euler"), std::string::npos) << w;
}

TEST(ConfiguredStability, OrderFourByTheDocumentedRuleIsStable)
{
  // The rule: var_y of order 4 at least 10 x its limit 8.5e7: the documented 1e9.
  const analysis::ConfiguredStability s = analysis::checkConfiguredStability(orderFour(1.0e9));
  ASSERT_TRUE(s.analysed) << s.reason;
  EXPECT_TRUE(s.stable) << s.spectral_radius;
  EXPECT_EQ(analysis::stabilityWarning(orderFour(1.0e9)), "");
  // Just below the limit the radius crosses 1.
  EXPECT_FALSE(analysis::checkConfiguredStability(orderFour(5.0e7)).stable);
}

TEST(ConfiguredStability, UnanalysableConfigurationIsReportedNotThrown)
{
  params::AicParams p = thesisEquivalent();
  p.belief_rate = 75.0;  // not a multiple of the action rate: the dual-rate model refuses it
  analysis::ConfiguredStability s;
  EXPECT_NO_THROW(s = analysis::checkConfiguredStability(p));
  EXPECT_FALSE(s.analysed);
  EXPECT_TRUE(s.stable);
  EXPECT_NE(s.reason.find("belief_rate / action_rate"), std::string::npos) << s.reason;
  EXPECT_EQ(analysis::stabilityWarning(p), "");
  p = thesisEquivalent();
  p.belief_model = params::BeliefModel::kRobot;  // not the linear model's: reported, not another model's radius
  EXPECT_NO_THROW(s = analysis::checkConfiguredStability(p));
  EXPECT_FALSE(s.analysed);
  EXPECT_TRUE(s.stable);
  EXPECT_NE(s.reason.find("belief_model robot"), std::string::npos) << s.reason;
  EXPECT_EQ(analysis::stabilityWarning(p), "");
  p = thesisEquivalent();
  p.k_a = -1.0;  // invalid parameters: reported, not thrown
  EXPECT_NO_THROW(s = analysis::checkConfiguredStability(p));
  EXPECT_FALSE(s.analysed);
  EXPECT_FALSE(s.reason.empty());
}
