/**
 * \file test_param_schema.cpp
 * \brief gtest (no roscore) of the parameter schema (include/jackal_aic/params/param_schema.hpp):
 *        the table's ranges drive validate(); the committed cfg/AIC.cfg and the table in
 *        doc/jackal_aic_node.md are what the schema generates; config/default.yaml holds only
 *        what has no default; config/\*.yaml name only known keys, document each with the
 *        schema's unit, repeat no default and are valid; `aic_params --yaml`; loading from
 *        YAML; the shared KEY=VALUE override parser (include/jackal_aic/overrides/yaml_overrides.hpp).
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "jackal_tools/param_docs.hpp"
#include "jackal_aic/params/param_schema.hpp"
#include "jackal_tools/params_yaml.hpp"
#include "jackal_aic/overrides/yaml_overrides.hpp"

namespace jackal_aic
{
namespace
{
const std::string kSource = SOURCE_DIR;

/// Every controller configuration shipped in config/ ("config/NAME.yaml", sorted).
std::vector<std::string> configFiles()
{
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(kSource + "/config"))
  {
    if (entry.path().extension() == ".yaml")
    {
      files.push_back("config/" + entry.path().filename().string());
    }
  }
  std::sort(files.begin(), files.end());
  EXPECT_GE(files.size(), 5u) << "config/ lost a configuration";
  return files;
}
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string readFile(const std::string& path)
{
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

params::NodeParams validNodeParams()
{
  params::NodeParams p;
  p.left_joints = { "front_left_wheel", "rear_left_wheel" };
  p.right_joints = { "front_right_wheel", "rear_right_wheel" };
  return p;
}

bool names(const std::vector<params::ParamViolation>& v, const std::string& name)
{
  for (const auto& x : v)
  {
    if (x.name == name)
    {
      return true;
    }
  }
  return false;
}

/// A value of a double row, or every element of a list row, set to x.
void setNumber(const params::ParamSpec& row, params::NodeParams* p, double x)
{
  if (row.type == params::ParamType::kDouble)
  {
    ASSERT_TRUE(row.set(*p, x));
  }
  else
  {
    auto list = std::get<std::vector<double>>(row.get(*p));
    list.assign(list.size(), x);
    ASSERT_TRUE(row.set(*p, list));
  }
}

/// The YAML comment block documenting each key of a config file: the comment lines right
/// above the key, from the line that starts with "# [unit]"; a key right below another key
/// (right_joints) shares that key's block.
std::map<std::string, std::string> commentBlocks(const std::string& path)
{
  std::map<std::string, std::string> blocks;
  std::ifstream in(path);
  std::string line;
  std::string block;
  std::string last_block;
  while (std::getline(in, line))
  {
    if (line.rfind("# [", 0) == 0)
    {
      block = line.substr(1) +
              "\n";  // a key's documentation starts with its unit (section headings before it do not count)
      continue;
    }
    if (line.rfind("#", 0) == 0)
    {
      block += line.substr(1) + "\n";
      continue;
    }
    const auto colon = line.find(':');
    if (!line.empty() && colon != std::string::npos && line[0] != ' ')
    {
      if (block.empty())
      {
        block = last_block;
      }
      blocks[line.substr(0, colon)] = block;
      last_block = block;
    }
    block.clear();
  }
  return blocks;
}
void expectDocumentedAsTheSchema(const std::string& path);
}  // namespace

TEST(ParamSchema, KeysAreUniqueAndDefaultsValid)
{
  std::set<std::string> keys;
  for (const params::ParamSpec& s : params::paramSchema())
  {
    EXPECT_TRUE(keys.insert(s.key).second) << s.key;
    EXPECT_EQ(params::findParam(s.key), &s);
    EXPECT_NE(std::string(s.description), "") << s.key;
    EXPECT_NE(std::string(s.unit), "") << s.key;
    if (s.numeric())
    {
      EXPECT_LE(s.min, s.max) << s.key;
    }
  }
  EXPECT_EQ(params::findParam("no_such_key"), nullptr);
  EXPECT_TRUE(validNodeParams().validate().empty());
  EXPECT_TRUE(params::AicParams().validate().empty());
}

TEST(ParamSchema, ControllerKeysAreTheMembersOfAicParams)
{
  // A controller key lives in NodeParams::aic (it survives copying only `aic`); a node key does not.
  for (const params::ParamSpec& s : params::paramSchema())
  {
    params::NodeParams p = validNodeParams();
    params::ParamValue changed;
    switch (s.type)
    {
      case params::ParamType::kDouble:
        changed = 0.123;
        break;
      case params::ParamType::kInt:
        changed = 2;
        break;
      case params::ParamType::kBool:
        changed = !std::get<bool>(s.get(params::NodeParams()));  // not the default (fdi_enabled defaults to true)
        break;
      case params::ParamType::kString: {
        // A choice other than the default (any text without choices).
        std::string other = "x";
        for (const auto& c : s.choices)
        {
          if (params::ParamValue(c) != params::defaultValue(s))
          {
            other = c;
          }
        }
        changed = other;
      }
      break;
      case params::ParamType::kDoubleList:
        changed = std::vector<double>{ 0.5, 0.5 };
        break;
      case params::ParamType::kStringList:
        changed = std::vector<std::string>{ "x" };
        break;
    }
    ASSERT_TRUE(s.set(p, changed)) << s.key;
    EXPECT_EQ(s.get(p), changed) << s.key;
    params::NodeParams only_aic;
    only_aic.aic = p.aic;
    EXPECT_EQ(s.get(only_aic) == changed, s.scope == params::ParamScope::kController) << s.key;
    EXPECT_FALSE(s.type != params::ParamType::kStringList && s.set(p, std::vector<std::string>{ "x" }))
        << s.key << ": took a value of the wrong type";
  }
  params::NodeParams p;
  ASSERT_TRUE(params::findParam("k_a")->set(p, 12.0));
  EXPECT_EQ(p.aic.k_a, 12.0);
  ASSERT_TRUE(params::findParam("sensor_timeout")->set(p, 0.3));
  EXPECT_EQ(p.sensor_timeout, 0.3);
  ASSERT_TRUE(params::findParam("integrator")->set(p, std::string("exact")));
  EXPECT_EQ(p.aic.integrator, params::Integrator::kExact);
  EXPECT_FALSE(params::findParam("integrator")->set(p, std::string("rk4")));
  EXPECT_EQ(p.aic.integrator, params::Integrator::kExact);
  ASSERT_TRUE(params::findParam("tau")->set(p, 2));  // an integer is a number
  EXPECT_EQ(p.aic.tau, 2.0);
}

TEST(ParamSchema, EachRowIsAMemberOfItsOwn)
{
  // Changing one key's member leaves every other key's value as it was: no two rows share a member.
  const params::NodeParams base = validNodeParams();
  for (const params::ParamSpec& s : params::paramSchema())
  {
    params::NodeParams p = base;
    params::ParamValue changed;
    switch (s.type)
    {
      case params::ParamType::kDouble:
        changed = std::get<double>(s.get(base)) + 0.125;
        break;
      case params::ParamType::kInt:
        changed = std::get<int>(s.get(base)) + 1;
        break;
      case params::ParamType::kBool:
        changed = !std::get<bool>(s.get(base));
        break;
      case params::ParamType::kString: {
        // Another choice (any text without choices).
        const std::string now = std::get<std::string>(s.get(base));
        changed = s.choices.empty() ? std::string("x") : s.choices.back() == now ? s.choices.front() : s.choices.back();
      }
      break;
      case params::ParamType::kDoubleList:
        changed = std::vector<double>{ 0.25 };
        break;
      case params::ParamType::kStringList:
        changed = std::vector<std::string>{ "x" };
        break;
    }
    ASSERT_NE(s.get(base), changed) << s.key;
    ASSERT_TRUE(s.set(p, changed)) << s.key;
    for (const params::ParamSpec& other : params::paramSchema())
    {
      if (std::string(other.key) != s.key)
      {
        EXPECT_EQ(other.get(p), other.get(base)) << "setting " << s.key << " changed " << other.key;
      }
    }
  }
}

TEST(ParamRow, NamedFieldsAndTheCommonRowAsDefaults)
{
  const params::ParamSpec row = params::ParamRow("active_inference", "latency")
                                    .unit("s")
                                    .atLeast(0.0)
                                    .describe("the robot model's latency")
                                    .member<&params::AicParams::robot, &params::RobotModelParams::latency>();
  EXPECT_EQ(row.type, params::ParamType::kDouble);
  EXPECT_EQ(row.scope, params::ParamScope::kController);
  EXPECT_EQ(row.min, 0.0);
  EXPECT_FALSE(row.min_exclusive);
  EXPECT_TRUE(std::isinf(row.max));
  EXPECT_TRUE(row.live);
  EXPECT_EQ(row.level, 0);
  EXPECT_FALSE(row.required);
  EXPECT_EQ(row.channels, 0);
  EXPECT_EQ(row.slots(), 0);
  params::AicParams p;
  ASSERT_TRUE(row.set_aic(p, 0.2));
  EXPECT_EQ(p.robot.latency, 0.2);
  EXPECT_EQ(row.get_aic(p), params::ParamValue(0.2));
  EXPECT_FALSE(row.set_aic(p, std::string("x")));

  const params::ParamSpec flag = params::ParamRow("active_inference", "tip_guard")
                                     .describe("the tip-over guard")
                                     .notLive()
                                     .member<&params::AicParams::tip_guard, &params::TipGuardParams::enabled>();
  EXPECT_EQ(flag.type, params::ParamType::kBool);
  EXPECT_FALSE(flag.live);
  EXPECT_TRUE(std::isnan(flag.min));
  EXPECT_TRUE(std::isnan(flag.max));
  EXPECT_EQ(flag.unit, std::string("-"));
}

TEST(ParamRow, AnIncompleteRowIsAnErrorNamingItsKey)
{
  const auto message = [](const params::ParamRow& row) -> std::string {
    try
    {
      const params::ParamSpec spec = row;
      return "";
    }
    catch (const std::logic_error& e)
    {
      return e.what();
    }
  };
  const std::string no_member = message(params::ParamRow("loops", "no_member").atLeast(0.0).describe("d"));
  EXPECT_NE(no_member.find("no_member: no member"), std::string::npos) << no_member;
  const std::string no_text =
      message(params::ParamRow("loops", "no_text").atLeast(0.0).member<&params::AicParams::tau>());
  EXPECT_NE(no_text.find("no_text: no description"), std::string::npos) << no_text;
  const std::string no_bound =
      message(params::ParamRow("loops", "no_bound").describe("d").member<&params::AicParams::tau>());
  EXPECT_NE(no_bound.find("no_bound: a number without a lower bound"), std::string::npos) << no_bound;
  EXPECT_EQ(message(params::ParamRow("loops", "complete").above(0.0).describe("d").member<&params::AicParams::tau>()),
            "");
}

TEST(ParamSchema, RangesDriveValidation)
{
  // For every number: the bounds themselves are allowed (the lower one unless exclusive),
  // beyond them, NaN and Inf are violations named by the key (or the list element).
  for (const params::ParamSpec& s : params::paramSchema())
  {
    if (s.type != params::ParamType::kDouble && s.type != params::ParamType::kDoubleList)
    {
      continue;
    }
    const std::string name = s.type == params::ParamType::kDouble ? s.key : std::string(s.key) + "[0]";
    auto violations = [&](double x) {
      params::NodeParams p = validNodeParams();
      setNumber(s, &p, x);
      return params::checkParamRanges(p, s.scope);
    };
    EXPECT_EQ(names(violations(s.min), name), s.min_exclusive) << s.key << " at its minimum " << s.min;
    EXPECT_TRUE(names(violations(s.min - std::max(1e-12, std::abs(s.min) * 1e-3)), name)) << s.key;
    if (std::isfinite(s.max))
    {
      EXPECT_FALSE(names(violations(s.max), name)) << s.key << " at its maximum " << s.max;
      EXPECT_TRUE(names(violations(s.max * 1.001), name)) << s.key;
    }
    EXPECT_TRUE(names(violations(std::numeric_limits<double>::quiet_NaN()), name)) << s.key;
    EXPECT_TRUE(names(violations(kInf), name)) << s.key;
  }
  params::NodeParams p = validNodeParams();
  p.aic.embedding_order = 6;
  EXPECT_TRUE(names(params::checkParamRanges(p, params::ParamScope::kController), "embedding_order"));
  p = validNodeParams();
  p.left_joints.clear();
  EXPECT_TRUE(names(params::checkParamRanges(p, params::ParamScope::kNode), "left_joints"));
  EXPECT_FALSE(names(params::checkParamRanges(p, params::ParamScope::kController), "left_joints"));
}

TEST(ParamSchema, NodeRulesBeyondTheTable)
{
  params::NodeParams p = validNodeParams();
  p.aic.belief_rate = 20000.0;  // within the core's sanity bound, beyond the node's timers
  EXPECT_TRUE(p.aic.validate().empty());
  EXPECT_TRUE(names(p.validate(), "belief_rate"));
  p = validNodeParams();
  p.min_sample_interval = 0.3;  // >= sensor_timeout
  EXPECT_TRUE(names(p.validate(), "min_sample_interval"));
  p = validNodeParams();
  p.right_joints = { "front_right_wheel", "front_left_wheel" };
  EXPECT_TRUE(names(p.validate(), "right_joints"));
  p = validNodeParams();
  p.left_joints = { "a", "a", "" };
  EXPECT_TRUE(names(p.validate(), "left_joints[1]"));
  EXPECT_TRUE(names(p.validate(), "left_joints[2]"));
}

TEST(ParamSchema, TextsForMessages)
{
  EXPECT_EQ(params::rangeText(*params::findParam("tau")), ">= 1e-06 and <= 1000, finite");
  EXPECT_EQ(params::rangeText(*params::findParam("k_a")), "> 0 and <= 1000000, finite");
  EXPECT_EQ(params::rangeText(*params::findParam("sensor_timeout")), "> 0 and finite");
  EXPECT_EQ(params::rangeText(*params::findParam("runaway_hold_time")), ">= 0 and finite");
  EXPECT_EQ(params::rangeText(*params::findParam("embedding_order")), "integer in [1, 5]");
  EXPECT_EQ(params::rangeText(*params::findParam("integrator")), "euler | exact");
  EXPECT_EQ(params::expectedText(*params::findParam("tau")), "a number");
  EXPECT_EQ(params::expectedText(*params::findParam("embedding_order")), "an integer");
  EXPECT_EQ(params::expectedText(*params::findParam("integrator")), "a string: euler or exact");
  EXPECT_EQ(params::expectedText(*params::findParam("var_y")), "a list of numbers");
  EXPECT_EQ(params::formatParamValue(std::vector<double>{ 1.5, 1e5 }), "[1.5, 100000]");
  for (double x : { 0.5621, 1e-6, 1e-9, 1e12, 1000.0, 0.025, 1.0 / 3.0, -2.5 })
  {
    EXPECT_EQ(std::strtod(shortestDecimal(x).c_str(), nullptr), x) << shortestDecimal(x);
  }
  EXPECT_EQ(shortestDecimal(1000.0), "1000");
  EXPECT_EQ(shortestDecimal(1e-6), "1e-6");
  EXPECT_EQ(shortestDecimal(1e12), "1e12");
}

TEST(ParamSchema, KeysWithoutEffect)
{
  EXPECT_EQ(params::beliefModelsText(params::kAllBeliefModels), "goal, unbiased and robot");
  EXPECT_EQ(params::beliefModelsText(params::kLinearBeliefModels), "goal and unbiased");
  EXPECT_EQ(params::beliefModelsText(params::kRobotBeliefModel), "robot");
  EXPECT_EQ(params::beliefModelsText(0u), "");
  for (const params::ParamSpec& row : params::paramSchema())
  {
    SCOPED_TRACE(row.key);
    EXPECT_NE(row.models, 0u) << "a key no model reads";
    EXPECT_EQ(row.models & ~params::kAllBeliefModels, 0u);
  }
  // The robot model: a goal-model key away from its default is listed, one at its default is not
  // (dynamic_reconfigure writes every live key back), nor a key it reads or one the schema lacks.
  params::NodeParams p;
  p.aic.belief_model = params::BeliefModel::kRobot;
  p.aic.tau = 0.02;
  p.aic.robot.latency = 0.2;
  const std::vector<std::string> set{ "k_mu", "latency", "tau", "no_such_key", "fdi_threshold" };
  std::vector<const params::ParamSpec*> listed = params::keysWithoutEffect(p, set);
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_STREQ(listed[0]->key, "tau");
  EXPECT_EQ(params::withoutEffectText(*listed[0], p), "tau = 0.02 has no effect with belief_model robot (read by the "
                                                      "goal and unbiased models only)");
  p.fdi.threshold = 1.0;  // the robot model tests its innovations at 5 standard deviations
  EXPECT_EQ(params::keysWithoutEffect(p, set).size(), 2u);
  // Over every key (the values in force, as the node's diagnostics list them): the same two.
  listed = params::keysWithoutEffect(p);
  ASSERT_EQ(listed.size(), 2u);
  EXPECT_STREQ(listed[0]->key, "tau");
  EXPECT_STREQ(listed[1]->key, "fdi_threshold");
  // The goal model: the robot model's keys, and the unbiased model's goal response.
  p.aic.belief_model = params::BeliefModel::kGoal;
  p.aic.goal_response_time_constant = 0.05;
  listed = params::keysWithoutEffect(p, { "tau", "latency", "goal_response_time_constant", "fdi_threshold" });
  ASSERT_EQ(listed.size(), 2u);
  EXPECT_EQ(params::withoutEffectText(*listed[0], p), "goal_response_time_constant = 0.05 has no effect with "
                                                      "belief_model goal (read by the unbiased model "
                                                      "only)");
  EXPECT_EQ(params::withoutEffectText(*listed[1], p), "latency = 0.2 has no effect with belief_model goal (read by the "
                                                      "robot model only)");
}

TEST(ParamSchema, ReconfigureEntries)
{
  std::set<std::string> names_seen;
  int slots = 0;
  for (const params::ReconfigureEntry& e : params::reconfigureEntries())
  {
    EXPECT_TRUE(names_seen.insert(e.name).second) << e.name;
    EXPECT_TRUE(e.row->live) << e.name;
    EXPECT_TRUE(params::isKnownKey(e.name, true)) << e.name;
    if (e.slot >= 0)
    {
      ++slots;
      EXPECT_EQ(e.type, params::ParamType::kDouble);
      EXPECT_EQ(e.name, std::string(e.row->key) + "_" + std::to_string(e.slot));
    }
    else
    {
      EXPECT_EQ(e.default_value, params::defaultValue(*e.row)) << e.name;
    }
  }
  EXPECT_EQ(slots, 2 * base::kMaxOrders);  // var_mu_0..5, var_y_0..5
  EXPECT_FALSE(params::isKnownKey("var_mu_0", false));
  EXPECT_TRUE(params::isKnownKey("diagnostic_period", false));
  EXPECT_FALSE(params::isKnownKey("sensor_timout", true));
  EXPECT_EQ(names_seen.count("left_joints"), 0u);          // not live
  EXPECT_EQ(names_seen.count("min_sample_interval"), 0u);  // not live
  // Slot defaults: the default list, its last element beyond it.
  for (const char* key : { "var_mu", "var_y" })
  {
    const params::ParamSpec& s = *params::findParam(key);
    ASSERT_EQ(s.slots(), base::kMaxOrders);
    const auto list = std::get<std::vector<double>>(params::defaultValue(s));
    ASSERT_LT(list.size(), static_cast<std::size_t>(base::kMaxOrders));
    EXPECT_EQ(params::slotDefault(s, 0), list.front());
    EXPECT_EQ(params::slotDefault(s, base::kMaxOrders - 1), list.back());
  }
}

TEST(ParamSchema, CfgFileIsGenerated)
{
  const std::string committed = readFile(kSource + "/cfg/AIC.cfg");
  EXPECT_EQ(committed, reconfigureCfgScript()) << "cfg/AIC.cfg differs from the schema: regenerate it with "
                                                  "`.ws/devel/lib/jackal_aic/aic_params --cfg > cfg/AIC.cfg`";
}

TEST(ParamSchema, DocTableIsGenerated)
{
  const std::string doc = readFile(kSource + "/doc/jackal_aic_node.md");
  const auto begin = doc.find(kParamTableBegin);
  const auto end = doc.find(kParamTableEnd);
  ASSERT_NE(begin, std::string::npos) << "doc/jackal_aic_node.md has no generated parameter table";
  ASSERT_NE(end, std::string::npos);
  const auto start = doc.find('\n', begin) + 1;
  EXPECT_EQ(doc.substr(start, end - start), parameterTableMarkdown()) << "the table in doc/jackal_aic_node.md differs "
                                                                         "from the schema: replace it with the output "
                                                                         "of "
                                                                         "`.ws/devel/lib/jackal_aic/aic_params "
                                                                         "--markdown`";
}

TEST(ParamSchema, DefaultYamlHoldsOnlyWhatHasNoDefault)
{
  // The defaults are written once, in the code (NodeParams, recommendedAicParams()):
  // config/default.yaml sets the keys that have none (the Jackal's joints) and the belief model it
  // drives with, the robot model, with the keys of its identified wheel loop and its goal's yaw
  // rate bound that differ from the schema's; it repeats no default. The defaults alone are a valid, not the diverging, controller.
  // Every config/*.yaml documents each of its keys with the schema's unit.
  const std::set<std::string> model_keys{ "belief_model",        "wheel_feedforward", "wheel_feedforward_acceleration",
                                          "wheel_time_constant", "learn_latency",     "max_goal_rate_angular" };
  const YAML::Node root = YAML::LoadFile(kSource + "/config/default.yaml");
  ASSERT_TRUE(root.IsMap());
  const params::NodeParams defaults;
  const params::NodeParams loaded = loadNodeParamsFiles({ kSource + "/config/default.yaml" });
  for (const params::ParamSpec& s : params::paramSchema())
  {
    SCOPED_TRACE(s.key);
    if (model_keys.count(s.key) != 0)
    {
      ASSERT_TRUE(bool(root[s.key])) << "the robot model's key missing from config/default.yaml";
      EXPECT_NE(params::formatParamValue(s.get(loaded)), params::formatParamValue(s.get(defaults))) << "config/"
                                                                                                       "default.yaml "
                                                                                                       "repeats a "
                                                                                                       "default";
      continue;
    }
    EXPECT_EQ(bool(root[s.key]), s.required)
        << (s.required ? "a required key missing from config/default.yaml" : "config/default.yaml repeats a default");
  }
  for (const auto& kv : root)
  {
    EXPECT_NE(params::findParam(kv.first.as<std::string>()), nullptr) << kv.first.as<std::string>();
  }
  const params::NodeParams p = loadNodeParamsFiles({ kSource + "/config/default.yaml" });
  EXPECT_TRUE(p.validate().empty());
  EXPECT_EQ(p.left_joints, (std::vector<std::string>{ "front_left_wheel", "rear_left_wheel" }));
  EXPECT_EQ(p.aic.integrator, params::Integrator::kExact);  // forward Euler at these gains diverges
  EXPECT_EQ(p.aic.belief_model, params::BeliefModel::kRobot);
  for (const std::string& file : configFiles())
  {
    expectDocumentedAsTheSchema(kSource + "/" + file);
  }
}

TEST(ParamSchema, EffectiveYamlLoadsBack)
{
  // `aic_params --yaml --config ...`: every key with the value the files give; loading that text
  // gives the same parameters, and the defaults' text (`aic_params --yaml`) gives the defaults.
  const std::vector<std::string> files = { kSource + "/config/default.yaml", kSource + "/config/robot.yaml" };
  const params::NodeParams robot = loadNodeParamsFiles(files);
  const std::string text = parameterYaml(&robot, files);
  EXPECT_NE(text.find("config/robot.yaml"), std::string::npos);
  params::NodeParams back;
  const params::ParamLoadReport r = params::loadParams(
      YamlParamSource(YAML::Load(text)), { params::ParamScope::kController, params::ParamScope::kNode }, false, &back);
  EXPECT_TRUE(r.errors.empty());
  EXPECT_TRUE(r.unknown.empty());
  EXPECT_TRUE(r.defaulted.empty());
  params::NodeParams defaults;
  const params::ParamLoadReport d =
      params::loadParams(YamlParamSource(YAML::Load(parameterYamlTemplate())),
                         { params::ParamScope::kController, params::ParamScope::kNode }, false, &defaults);
  EXPECT_TRUE(d.errors.empty());
  for (const params::ParamSpec& s : params::paramSchema())
  {
    SCOPED_TRACE(s.key);
    EXPECT_EQ(params::formatParamValue(s.get(back)), params::formatParamValue(s.get(robot)));
    EXPECT_TRUE(s.get(defaults) == params::defaultValue(s));
  }
  EXPECT_NE(robot.aic.reference.delay, params::NodeParams().aic.reference.delay);  // the overlay's key
}

namespace
{
/// The overlays in config/ and the files loaded before each (launch/robot.launch: default.yaml,
/// robot.yaml, then the user's overlay such as first_run.yaml).
const std::map<std::string, std::vector<std::string>>& overlayBases()
{
  static const std::map<std::string, std::vector<std::string>> bases{
    { "config/robot.yaml", { "config/default.yaml" } },
    { "config/first_run.yaml", { "config/default.yaml", "config/robot.yaml" } },
    { "config/unbiased.yaml", { "config/default.yaml", "config/robot.yaml" } },
    { "config/goal_model.yaml", { "config/default.yaml", "config/robot.yaml" } },
  };
  return bases;
}
}  // namespace

TEST(ParamSchema, OverlaysHoldOnlyWhatDiffers)
{
  // config/robot.yaml and config/first_run.yaml are loaded after config/default.yaml
  // (launch/robot.launch): each holds only keys that differ from what its bases give (each with
  // its bases is checked in EveryConfigFileIsValid).
  for (const auto& [file, bases] : overlayBases())
  {
    SCOPED_TRACE(file);
    std::vector<std::string> base_files;
    for (const std::string& b : bases)
    {
      base_files.push_back(kSource + "/" + b);
    }
    const params::NodeParams base = loadNodeParamsFiles(base_files);
    const YAML::Node overlay = YAML::LoadFile(kSource + "/" + file);
    ASSERT_TRUE(overlay.IsMap());
    ASSERT_GT(overlay.size(), 0u);
    for (const auto& kv : overlay)
    {
      const std::string key = kv.first.as<std::string>();
      SCOPED_TRACE(key);
      const params::ParamSpec* s = params::findParam(key);
      ASSERT_NE(s, nullptr) << "unknown key in the overlay";
      YAML::Node one;
      one[key] = kv.second;
      params::NodeParams from_yaml;
      ASSERT_TRUE(params::loadParams(YamlParamSource(one),
                                     { params::ParamScope::kController, params::ParamScope::kNode }, false, &from_yaml)
                      .errors.empty());
      EXPECT_FALSE(s->get(from_yaml) == s->get(base)) << "a key of the overlay that repeats what its bases give";
    }
  }
}

TEST(ParamSchema, RobotYamlStopsNoLaterThanTheStockDiffDrive)
{
  // When twist_mux falls silent the stock diff drive commands zero after its cmd_vel_timeout
  // (0.25 s, jackal_control config/control.yaml) at its next cycle; the AIC after
  // set_point_timeout, noticed at its next sample or action tick (one 50 Hz period), and the
  // diff drive applies the zero at its next cycle (another period): config/robot.yaml's
  // comment. The first-run overlay keeps it.
  constexpr double kStockCmdVelTimeout = 0.25;  // s
  constexpr double kCycle = 0.02;               // s, 50 Hz
  const params::NodeParams robot = loadNodeParamsFiles({ kSource + "/config/default.yaml", kSource + "/config/"
                                                                                                     "robot.yaml" });
  EXPECT_LE(robot.set_point_timeout + 2.0 * kCycle, kStockCmdVelTimeout);
  const params::NodeParams first = loadNodeParamsFiles(
      { kSource + "/config/default.yaml", kSource + "/config/robot.yaml", kSource + "/config/first_run.yaml" });
  EXPECT_EQ(first.set_point_timeout, robot.set_point_timeout);
  EXPECT_LT(first.max_linear_speed, robot.max_linear_speed);
  EXPECT_LT(first.max_angular_speed, robot.max_angular_speed);
  EXPECT_LT(first.aic.max_wheel_speed, robot.aic.max_wheel_speed);
  EXPECT_EQ(first.aic.reference.delay, robot.aic.reference.delay);  // stacked, not replaced
}

namespace
{
/// Each key of a config file documented with the schema's unit and default.
void expectDocumentedAsTheSchema(const std::string& path)
{
  const auto blocks = commentBlocks(path);
  for (const auto& [key, block] : blocks)
  {
    SCOPED_TRACE(path + ": " + key);
    EXPECT_TRUE(params::isKnownKey(key, false));
    const params::ParamSpec* s = params::findParam(key);
    if (s == nullptr)
    {
      continue;
    }
    EXPECT_EQ(block.rfind(std::string(" [") + s->unit + "] ", 0), 0u) << "unit: " << block;
    EXPECT_EQ(block.find("Default: "), std::string::npos) << "a config file repeats a default (the schema's; "
                                                             "`aic_params --yaml` prints them)";
  }
}
}  // namespace

TEST(ParamSchema, EveryConfigFileIsValid)
{
  std::vector<std::string> files = configFiles();
  files.insert(files.end(), { "test/data/thesis_standard.yaml", "test/data/thesis_improved_euler_diverges.yaml" });
  for (const std::string& file : files)
  {
    SCOPED_TRACE(file);
    params::NodeParams p;
    const auto overlay = overlayBases().find(file);
    if (overlay != overlayBases().end())  // an overlay: loaded after its bases
    {
      for (const std::string& base : overlay->second)
      {
        ASSERT_TRUE(params::loadParams(YamlParamSource(YAML::LoadFile(kSource + "/" + base)),
                                       { params::ParamScope::kController, params::ParamScope::kNode }, false, &p)
                        .errors.empty());
      }
    }
    const params::ParamLoadReport r =
        params::loadParams(YamlParamSource(YAML::LoadFile(kSource + "/" + file)),
                           { params::ParamScope::kController, params::ParamScope::kNode }, false, &p);
    EXPECT_TRUE(r.errors.empty()) << r.errors.front().toString();
    EXPECT_TRUE(r.unknown.empty()) << r.unknown.front();
    for (const auto& v : p.validate())
    {
      ADD_FAILURE() << v.toString();
    }
  }
}

TEST(ParamSchema, LoadFromYaml)
{
  const YAML::Node root = YAML::Load("tau: 0.02\nk_a: 3\nembedding_order: 2\nvar_mu: [1, 2, 3]\n"
                                     "sensor_timeout: fast\nintegrator: rk4\nbogus: 1\ndiagnostic_period: 1\n");
  params::NodeParams p;
  const params::ParamLoadReport r = params::loadParams(
      YamlParamSource(root), { params::ParamScope::kController, params::ParamScope::kNode }, false, &p);
  EXPECT_EQ(p.aic.tau, 0.02);
  EXPECT_EQ(p.aic.k_a, 3.0);
  EXPECT_EQ(p.aic.embedding_order, 2);
  EXPECT_EQ(p.aic.var_mu, (std::vector<double>{ 1, 2, 3 }));
  ASSERT_EQ(r.errors.size(), 2u);
  EXPECT_EQ(r.errors[0].toString(), "integrator = rk4 (allowed: a string: euler or exact)");
  EXPECT_EQ(r.errors[1].toString(), "sensor_timeout = fast (allowed: a number)");
  EXPECT_EQ(r.unknown, std::vector<std::string>{ "bogus" });
  EXPECT_NE(std::find(r.defaulted.begin(), r.defaulted.end(), "k_mu"), r.defaulted.end());
  EXPECT_NE(std::find(r.defaulted.begin(), r.defaulted.end(), "left_joints"), r.defaulted.end());

  // The tools read the controller keys only; a type error names the key and the type.
  std::vector<std::string> defaulted, unknown;
  const YAML::Node tool = YAML::Load("tau: 0.02\nsensor_timeout: 0.3\n");
  EXPECT_EQ(aicParamsFromYaml(tool, "f.yaml", &defaulted, &unknown).tau, 0.02);
  EXPECT_TRUE(unknown.empty());
  EXPECT_EQ(std::find(defaulted.begin(), defaulted.end(), "sensor_timeout"), defaulted.end());
  try
  {
    aicParamsFromYaml(YAML::Load("embedding_order: 1.5\n"), "f.yaml", nullptr, nullptr);
    ADD_FAILURE() << "no error";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_EQ(std::string(e.what()), "f.yaml: key 'embedding_order' must be an integer (got 1.5)");
  }
}

TEST(YamlOverrides, ParseAndApply)
{
  EXPECT_EQ(overrides::parseOverride("tau=0.01").key, "tau");
  EXPECT_EQ(overrides::parseOverride("tau=0.01").value, "0.01");
  EXPECT_EQ(overrides::parseOverride("var_y=[2, 20]").value, "[2, 20]");
  EXPECT_EQ(overrides::parseOverride("a.b=x=y").value, "x=y");  // split at the first '='
  for (const char* bad : { "tau", "=1", "a..b=1", ".a=1", "a.=1", "" })
  {
    EXPECT_THROW(overrides::parseOverride(bad), std::invalid_argument) << bad;
  }
  YAML::Node root = YAML::Load("tau: 0.1\nmotor: {delay: 0.1, gain: 2}\n");
  overrides::applyOverrides(root,
                            { "tau=0.01", "motor.delay=0.05", "sensors.imu.rate=100", "var_y=[1, 2]", "tau=0.02" });
  EXPECT_EQ(root["tau"].as<double>(), 0.02);  // later overrides win
  EXPECT_EQ(root["motor"]["delay"].as<double>(), 0.05);
  EXPECT_EQ(root["motor"]["gain"].as<double>(), 2.0);
  EXPECT_EQ(root["sensors"]["imu"]["rate"].as<int>(), 100);
  EXPECT_EQ(root["var_y"].as<std::vector<double>>(), (std::vector<double>{ 1, 2 }));
  // Nothing is applied when one override is bad.
  YAML::Node untouched = YAML::Load("tau: 0.1\n");
  EXPECT_THROW(overrides::applyOverrides(untouched, { "tau=0.5", "k_a=[1," }), std::invalid_argument);
  EXPECT_EQ(untouched["tau"].as<double>(), 0.1);
  EXPECT_THROW(overrides::applyOverrides(untouched, { "tau" }), std::invalid_argument);
}

TEST(YamlOverrides, OverlayFlattensToOverrides)
{
  const YAML::Node overlay = YAML::Load("motor: {speed_ki: 8, limits: {max: 4}}\ncontact: {mu1: 0.3}\nbias: [0, 0, "
                                        "0.01]\n");
  const std::vector<std::string> o = overrides::overlayOverrides(overlay, "variant.yaml");
  EXPECT_EQ(o, (std::vector<std::string>{ "motor.speed_ki=8", "motor.limits.max=4", "contact.mu1=0.3",
                                          "bias=[0, 0, 0.01]" }));
  // Applied on a base file, the overlay changes only its own keys.
  YAML::Node base = YAML::Load("motor: {speed_ki: 1, speed_kp: 15}\ncontact: {mu1: 0.5, mu2: 0.5}\n");
  overrides::applyOverrides(base, o);
  EXPECT_EQ(base["motor"]["speed_ki"].as<double>(), 8.0);
  EXPECT_EQ(base["motor"]["speed_kp"].as<double>(), 15.0);
  EXPECT_EQ(base["contact"]["mu2"].as<double>(), 0.5);
  EXPECT_EQ(base["bias"].as<std::vector<double>>(), (std::vector<double>{ 0, 0, 0.01 }));
  EXPECT_TRUE(overrides::overlayOverrides(YAML::Load(""), "empty.yaml").empty());
  EXPECT_THROW(overrides::overlayOverrides(YAML::Load("[1, 2]"), "list.yaml"), std::invalid_argument);
  EXPECT_THROW(overrides::overlayOverrides(YAML::Load("{a.b: 1}"), "dotted.yaml"), std::invalid_argument);
  EXPECT_THROW(overrides::loadOverlayFile("/no/such/overlay.yaml"), std::invalid_argument);
}

TEST(YamlOverrides, LoadAicParamsAppliesAndValidates)
{
  const std::string file = kSource + "/config/thesis_standard.yaml";
  EXPECT_EQ(loadAicParams(file, { "tau=0.01", "integrator=exact" }).tau, 0.01);
  EXPECT_EQ(loadAicParams(file, { "integrator=exact" }).integrator, params::Integrator::kExact);
  EXPECT_THROW(loadAicParams(file, { "tau=-1" }), std::runtime_error);
  EXPECT_THROW(loadAicParams(file, { "tau" }), std::runtime_error);
  EXPECT_THROW(loadAicParams(kSource + "/no/such/file.yaml"), std::runtime_error);
}

TEST(YamlOverrides, AnErrorAnOverrideCausesNamesTheOverride)
{
  // var_mu of two elements for embedding order 2: the list is the override's, not the file's.
  const std::string file = kSource + "/config/default.yaml";
  for (const bool node : { true, false })
  {
    try
    {
      if (node)
      {
        loadNodeParamsFiles({ file }, { "var_mu=[1, 2]" });
      }
      else
      {
        loadAicParams(file, { "var_mu=[1, 2]" });
      }
      FAIL() << "accepted var_mu of two elements";
    }
    catch (const std::runtime_error& e)
    {
      EXPECT_NE(std::string(e.what()).find(file + " with --aic-set var_mu=[1, 2]: invalid parameters"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(YamlOverrides, LoadNodeParamsFilesReadsBothScopesInOrder)
{
  // config/robot.yaml over config/default.yaml, as robot.launch loads them; node keys too.
  const params::NodeParams robot = loadNodeParamsFiles({ kSource + "/config/default.yaml", kSource + "/config/"
                                                                                                     "robot.yaml" });
  const params::NodeParams base = loadNodeParamsFiles({ kSource + "/config/default.yaml" });
  EXPECT_NE(robot.aic.reference.delay, base.aic.reference.delay);
  EXPECT_EQ(robot.aic.k_a, base.aic.k_a);
  EXPECT_EQ(robot.aic.tau, base.aic.tau);
  const params::NodeParams node = loadNodeParamsFiles(
      { kSource + "/config/default.yaml" }, { "action_trigger=timer", "belief_schedule=timer", "fdi_enabled=false" });
  EXPECT_EQ(node.action_trigger, params::ActionTrigger::kTimer);
  EXPECT_EQ(node.belief_schedule, params::BeliefSchedule::kTimer);
  EXPECT_FALSE(node.fdi.enabled);
  // Errors name the file and the key; invalid values list every violation.
  try
  {
    loadNodeParamsFiles({ kSource + "/config/default.yaml" }, { "belief_schedule=sometimes", "tau=-1" });
    FAIL() << "accepted an unknown belief_schedule";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_NE(std::string(e.what()).find("belief_schedule"), std::string::npos) << e.what();
  }
  try
  {
    loadNodeParamsFiles({ kSource + "/config/default.yaml" }, { "tau=-1", "sensor_timeout=0" });
    FAIL() << "accepted invalid values";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_NE(std::string(e.what()).find("tau"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("sensor_timeout"), std::string::npos) << e.what();
  }
  EXPECT_THROW(loadNodeParamsFiles({ kSource + "/no/such/file.yaml" }), std::runtime_error);
}

}  // namespace jackal_aic
