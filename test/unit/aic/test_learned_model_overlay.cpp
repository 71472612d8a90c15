/// Tests of learnedModel() and learnedModelOverlay(): what the controller learned (the wheel
/// separation, the robot model's latency) and the YAML overlay ~save_learned_model writes of it
/// (doc/jackal_aic_node.md, 'Learned model').
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "jackal_aic/aic/controller.hpp"
#include "jackal_aic/aic/learned_model_overlay.hpp"
#include "jackal_aic/params/node_params.hpp"
#include "jackal_aic/params/param_schema.hpp"

#include "wheel_loop_drive.hpp"

using namespace jackal_aic;
using Status = aic::ActiveInferenceController::Status;

namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The overlay's "key: value" lines (the comments skipped), in order.
std::vector<std::pair<std::string, std::string>> keyLines(const std::string& text)
{
  std::vector<std::pair<std::string, std::string>> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
    {
      continue;
    }
    const std::size_t colon = line.find(": ");
    EXPECT_NE(colon, std::string::npos) << line;
    lines.emplace_back(line.substr(0, colon), line.substr(colon + 2));
  }
  return lines;
}

/// The overlay as the node reads it: its keys as doubles, through the parameter schema.
class OverlaySource : public params::ParamSource
{
public:
  explicit OverlaySource(const std::string& text)
  {
    for (const auto& [key, value] : keyLines(text))
    {
      values_[key] = std::stod(value);
    }
  }
  Status read(const std::string& key, params::ParamType type, params::ParamValue* out) const override
  {
    const auto it = values_.find(key);
    if (it == values_.end())
    {
      return Status::kMissing;
    }
    if (type != params::ParamType::kDouble)
    {
      return Status::kWrongType;
    }
    *out = it->second;
    return Status::kOk;
  }
  std::string raw(const std::string& key) const override
  {
    const auto it = values_.find(key);
    return it == values_.end() ? "<missing>" : std::to_string(it->second);
  }
  std::vector<std::string> keys() const override
  {
    std::vector<std::string> k;
    for (const auto& [key, value] : values_)
    {
      k.push_back(key);
    }
    return k;
  }

private:
  std::map<std::string, double> values_;
};

aic::LearnedModel learned(std::optional<double> b, std::optional<double> latency, int starts)
{
  aic::LearnedModel m;
  m.wheel_separation = b;
  m.latency = latency;
  m.latency_starts = starts;
  return m;
}

/// The robot model (L = 0.1187 s) against a wheel-loop plant whose commands act 0.1424 s later,
/// 1 s from rest to a 0.5 m/s goal: one start from rest.
void driveOneStart(aic::ActiveInferenceController* c)
{
  params::RobotModelParams truth = c->params().robot;
  truth.latency = 0.1424;
  jackal_test::driveAgainstWheelLoop(c, truth, base::Vector3(0.5, 0.0, 0.0));
}
}  // namespace

TEST(LearnedModelOverlay, WritesEachLearnedValueAfterItsComments)
{
  const std::string text = aic::learnedModelOverlay(learned(0.786940123, 0.14237891, 3));
  const auto lines = keyLines(text);
  ASSERT_EQ(lines.size(), 2u) << text;
  EXPECT_EQ(lines[0], std::make_pair(std::string("wheel_separation"), std::string("0.78694")));
  EXPECT_EQ(lines[1], std::make_pair(std::string("latency"), std::string("0.142379")));
  // Each value follows a comment naming how it was learned and one naming its unit.
  EXPECT_NE(text.find("(learn_wheel_separation;"), std::string::npos) << text;
  EXPECT_NE(text.find("# [m] Wheel separation b_hat"), std::string::npos) << text;
  EXPECT_NE(text.find("first motion after rest, the running\n# mean of 3 starts (learn_latency;"), std::string::npos)
      << text;
  EXPECT_NE(text.find("# [s] Robot model: L, /cmd_drive to the wheels' response.\nlatency: "), std::string::npos)
      << text;
  EXPECT_NE(aic::learnedModelOverlay(learned(std::nullopt, 0.1, 1)).find("mean of 1 start ("), std::string::npos);
}

TEST(LearnedModelOverlay, WritesOnlyWhatWasLearned)
{
  const std::string separation = aic::learnedModelOverlay(learned(0.6, std::nullopt, 0));
  ASSERT_EQ(keyLines(separation).size(), 1u) << separation;
  EXPECT_EQ(keyLines(separation)[0].first, "wheel_separation");
  EXPECT_EQ(separation.find("learn_latency"), std::string::npos) << separation;

  const std::string latency = aic::learnedModelOverlay(learned(std::nullopt, 0.1187, 2));
  ASSERT_EQ(keyLines(latency).size(), 1u) << latency;
  EXPECT_EQ(keyLines(latency)[0], std::make_pair(std::string("latency"), std::string("0.1187")));
  EXPECT_EQ(latency.find("learn_wheel_separation"), std::string::npos) << latency;
}

TEST(LearnedModelOverlay, TheNodeReadsItsKeysIntoTheLearnedValues)
{
  // Loaded through the parameter schema (as the node loads ~ after the other configs): every key
  // is known, of the right type, lands in the member the controller's model and learners take,
  // and is within the node's range.
  const std::string text = aic::learnedModelOverlay(learned(0.6123, 0.2374, 4));
  params::NodeParams p;
  p.aic.belief_model = params::BeliefModel::kRobot;
  const params::ParamLoadReport report =
      params::loadParams(OverlaySource(text), { params::ParamScope::kController }, false, &p);
  EXPECT_TRUE(report.errors.empty());
  EXPECT_TRUE(report.unknown.empty());
  EXPECT_EQ(p.aic.wheel_separation, 0.6123);
  EXPECT_EQ(p.aic.robot.latency, 0.2374);
  EXPECT_TRUE(params::checkParamRanges(p.aic).empty());
  // The largest latency the overlay writes is the largest the node accepts.
  p.aic.robot.latency = params::kMaxReferenceDelay;
  EXPECT_TRUE(params::checkParamRanges(p.aic).empty());
  p.aic.robot.latency = std::nextafter(params::kMaxReferenceDelay, 1.0);
  EXPECT_FALSE(params::checkParamRanges(p.aic).empty());
}

TEST(LearnedModelOverlay, RefusesBadValues)
{
  EXPECT_THROW(aic::learnedModelOverlay(aic::LearnedModel()), std::invalid_argument);  // nothing learned
  for (const double b : { 0.0, -0.5, kNaN, kInf })
  {
    SCOPED_TRACE(b);
    EXPECT_THROW(aic::learnedModelOverlay(learned(b, std::nullopt, 0)), std::invalid_argument);
    EXPECT_THROW(aic::learnedModelOverlay(learned(b, 0.1, 1)), std::invalid_argument);
  }
  for (const double l : { 0.0, -0.1, kNaN, kInf, std::nextafter(params::kMaxReferenceDelay, 1.0) })
  {
    SCOPED_TRACE(l);
    EXPECT_THROW(aic::learnedModelOverlay(learned(std::nullopt, l, 1)), std::invalid_argument);
    EXPECT_THROW(aic::learnedModelOverlay(learned(0.6, l, 1)), std::invalid_argument);
  }
  EXPECT_NO_THROW(aic::learnedModelOverlay(learned(std::nullopt, params::kMaxReferenceDelay, 1)));
  EXPECT_THROW(aic::learnedModelOverlay(learned(std::nullopt, 0.1, 0)), std::invalid_argument);  // no start
  try
  {
    aic::learnedModelOverlay(learned(kNaN, -1.0, 0));
    ADD_FAILURE() << "no throw";
  }
  catch (const std::invalid_argument& e)
  {
    const std::string what = e.what();
    EXPECT_NE(what.find("wheel_separation = nan m"), std::string::npos) << what;
    EXPECT_NE(what.find("latency = -1 s"), std::string::npos) << what;
    EXPECT_NE(what.find("latency_starts = 0"), std::string::npos) << what;
  }
}

TEST(LearnedModel, TakesWhatTheLearnersOnLearned)
{
  params::AicParams p = params::recommendedAicParams();
  p.separation_learner.enabled = true;
  {
    const aic::LearnedModel m = aic::learnedModel(aic::ActiveInferenceController(p));
    ASSERT_TRUE(m.wheel_separation.has_value());
    EXPECT_EQ(*m.wheel_separation, p.wheel_separation);
    EXPECT_FALSE(m.latency.has_value());
  }
  p.separation_learner.enabled = false;
  EXPECT_FALSE(aic::learnedModel(aic::ActiveInferenceController(p)).wheel_separation.has_value());

  // The robot model with learn_latency: no latency before a start from rest, the learned one after.
  p.belief_model = params::BeliefModel::kRobot;
  p.robot.learn_latency = true;
  aic::ActiveInferenceController c(p);
  EXPECT_FALSE(aic::learnedModel(c).latency.has_value());
  driveOneStart(&c);
  ASSERT_EQ(c.latencyLearner().starts(), 1);
  aic::LearnedModel m = aic::learnedModel(c);
  ASSERT_TRUE(m.latency.has_value());
  EXPECT_EQ(*m.latency, c.wheelLoop().latency());
  EXPECT_NEAR(*m.latency, 0.1424, 2e-3);
  EXPECT_EQ(m.latency_starts, 1);
  EXPECT_FALSE(m.wheel_separation.has_value());
  EXPECT_EQ(keyLines(aic::learnedModelOverlay(m)).size(), 1u);

  // Forgotten by resetLearning(); not taken from another belief model or with learn_latency off.
  aic::ActiveInferenceController reset = c;
  reset.resetLearning();
  EXPECT_FALSE(aic::learnedModel(reset).latency.has_value());
  params::AicParams other = p;
  other.belief_model = params::BeliefModel::kUnbiased;
  aic::ActiveInferenceController unbiased = c;
  unbiased.setParams(other);
  ASSERT_EQ(unbiased.latencyLearner().starts(), 1);  // kept across the change, but not this model's
  EXPECT_FALSE(aic::learnedModel(unbiased).latency.has_value());
  other = p;
  other.robot.learn_latency = false;
  aic::ActiveInferenceController off = c;
  off.setParams(other);
  EXPECT_FALSE(aic::learnedModel(off).latency.has_value());
}
