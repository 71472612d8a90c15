/// Bad-input paths and basic output of the CLI tools aic_analyze, aic_step_metrics and aic_predict.
#include <gtest/gtest.h>

#include "jackal_test/run_command.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace
{
using Result = jackal_test::CommandResult;
constexpr auto* run = &jackal_test::runCommand;

std::string writeFile(const std::string& name, const std::string& text)
{
  const std::string path = std::string(::testing::TempDir()) + name;
  std::ofstream(path) << text;
  return path;
}

/// The number that follows the first occurrence of `key` in `text` (NaN if none).
double numberAfter(const std::string& text, const std::string& key)
{
  const auto at = text.find(key);
  return at == std::string::npos ? std::nan("") : std::strtod(text.c_str() + at + key.size(), nullptr);
}

/// The comma-separated fields of the first line of `text` that starts with `prefix` (empty if none).
std::vector<std::string> csvRow(const std::string& text, const std::string& prefix)
{
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line))
  {
    if (line.rfind(prefix, 0) == 0)
    {
      std::vector<std::string> fields;
      std::istringstream cells(line);
      std::string cell;
      while (std::getline(cells, cell, ','))
      {
        fields.push_back(cell);
      }
      return fields;
    }
  }
  return {};
}

/// The value text of a top-level `key: value` line of a YAML file (comment cut, trimmed), or "".
std::string yamlScalar(const std::string& path, const std::string& key)
{
  std::ifstream f(path);
  std::string line;
  while (std::getline(f, line))
  {
    if (line.rfind(key + ":", 0) == 0)
    {
      std::string v = line.substr(key.size() + 1);
      v = v.substr(0, v.find('#'));
      const auto b = v.find_first_not_of(" \t"), e = v.find_last_not_of(" \t");
      return b == std::string::npos ? "" : v.substr(b, e - b + 1);
    }
  }
  return "";
}

const std::string kAnalyze = AIC_ANALYZE_BIN;
const std::string kMetrics = AIC_STEP_METRICS_BIN;
const std::string kData = TEST_DATA_DIR;
}  // namespace

TEST(AicAnalyze, ThesisSetsShowBeliefStiffness)
{
  const Result r = run(kAnalyze + " " + kData +
                       "/thesis_improved_euler_diverges.yaml --csv --rates 1000 --no-scan"
                       " --plant-time-constant 0.15");
  ASSERT_EQ(r.code, 0) << r.out;
  // Each row's own stable column: forward Euler unstable (spectral radius > 1), exact stable.
  const std::vector<std::string> euler = csvRow(r.out, "1000,50,euler,");
  const std::vector<std::string> exact = csvRow(r.out, "1000,50,exact,");
  ASSERT_GE(euler.size(), 5u) << r.out;
  ASSERT_GE(exact.size(), 5u) << r.out;
  EXPECT_GT(std::stod(euler[3]), 1.0);
  EXPECT_EQ(euler[4], "false");
  EXPECT_EQ(exact[3].rfind("0.98", 0), 0u) << exact[3];
  EXPECT_EQ(exact[4], "true");
}

TEST(AicAnalyze, BadArgumentsAndFiles)
{
  EXPECT_EQ(run(kAnalyze).code, 2);
  EXPECT_EQ(run(kAnalyze + " " + kData + "/thesis_standard.yaml --bogus").code, 2);
  EXPECT_EQ(run(kAnalyze + " " + kData + "/thesis_standard.yaml --rates 50,x").code, 2);
  EXPECT_EQ(run(kAnalyze + " " + kData + "/thesis_standard.yaml --rates 75 --no-scan").code, 2);
  EXPECT_EQ(run(kAnalyze + " " + kData + "/thesis_standard.yaml --integrators rk4").code, 2);
  const Result missing = run(kAnalyze + " /nonexistent/file.yaml");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.out.find("cannot read"), std::string::npos);
  const Result invalid = run(kAnalyze + " " + writeFile("aic_bad.yaml", "tau: -1\nfoo: 2\n") + " --no-scan");
  EXPECT_EQ(invalid.code, 1);
  EXPECT_NE(invalid.out.find("tau = -1"), std::string::npos) << invalid.out;
  EXPECT_NE(invalid.out.find("unknown key 'foo'"), std::string::npos) << invalid.out;
  EXPECT_EQ(run(kAnalyze + " " + writeFile("aic_type.yaml", "k_mu: [1, 2]\n")).code, 1);
  // A key of the wrong type is an error naming the key and the expected type.
  const std::pair<const char*, const char*> kTypeErrors[] = {
    { "tau: fast\n", "key 'tau' must be a number" },
    { "embedding_order: 1.5\n", "key 'embedding_order' must be an integer" },
    { "var_y: 2\n", "key 'var_y' must be a list of numbers" },
    { "accel_in_model: maybe\n", "key 'accel_in_model' must be true or false" },
    { "integrator: [euler]\n", "key 'integrator' must be a string" },
  };
  for (const auto& [yaml, message] : kTypeErrors)
  {
    const Result typed = run(kAnalyze + " " + writeFile("aic_typed.yaml", yaml) + " --no-scan");
    EXPECT_EQ(typed.code, 1) << yaml;
    EXPECT_NE(typed.out.find(message), std::string::npos) << yaml << typed.out;
  }
  EXPECT_EQ(run(kAnalyze + " " + writeFile("aic_syntax.yaml", "tau: [\n")).code, 1);
  EXPECT_EQ(run(kAnalyze + " " + writeFile("aic_integ.yaml", "integrator: rk4\n")).code, 1);
  // A belief model the linear model does not represent is an error, not the goal model's figures.
  for (const char* model : { "robot", "unbiased" })
  {
    const Result other =
        run(kAnalyze + " " + writeFile("aic_model.yaml", std::string("belief_model: ") + model + "\n") + " --no-scan");
    EXPECT_EQ(other.code, 1) << model << other.out;
    EXPECT_NE(other.out.find(std::string("belief_model ") + model + " is not represented"), std::string::npos)
        << other.out;
  }
}

TEST(AicAnalyze, NodeOnlyKeysAreNotWarnedAbout)
{
  // Every node-only key of config/*.yaml (NodeParams) is ignored quietly; a typo is still warned about.
  const std::string yaml = "sensor_timeout: 0.25\nset_point_timeout: 0.5\nimu_max_skew: 0.025\nmin_sample_interval: "
                           "0.005\n"
                           "max_linear_speed: 2.0\nmax_angular_speed: 4.0\nrunaway_hold_time: 1.0\ndiagnostic_period: "
                           "1.0\n"
                           "left_joints: [front_left_wheel, rear_left_wheel]\nright_joints: [front_right_wheel, "
                           "rear_right_wheel]\n";
  const Result quiet = run(kAnalyze + " " + writeFile("aic_node_keys.yaml", yaml) + " --no-scan");
  EXPECT_EQ(quiet.code, 0) << quiet.out;
  EXPECT_EQ(quiet.out.find("unknown key"), std::string::npos) << quiet.out;
  const Result typo = run(kAnalyze + " " + writeFile("aic_typo.yaml", yaml + "sensor_timout: 0.25\n") + " --no-scan");
  EXPECT_NE(typo.out.find("unknown key 'sensor_timout'"), std::string::npos) << typo.out;
}

TEST(AicStepMetrics, ComputesAndRejects)
{
  std::string csv = "time,value\n";
  for (int k = 0; k <= 100; ++k)
  {
    csv += std::to_string(k * 0.01) + "," + (k < 10 ? "0" : "1") + "\n";
  }
  const std::string path = writeFile("aic_step.csv", csv);
  const Result ok = run(kMetrics + " " + path + " --step-time 0.1 --initial 0 --target 1");
  ASSERT_EQ(ok.code, 0) << ok.out;
  EXPECT_NE(ok.out.find("\"overshoot_percent\": 0"), std::string::npos) << ok.out;
  EXPECT_EQ(run(kMetrics + " " + path + " --initial 0 --target 1").code, 2);                        // no step time
  EXPECT_EQ(run(kMetrics + " " + path + " --step-time 0.1 --initial 0 --target 1 --x 1").code, 2);  // unknown option
  EXPECT_EQ(run(kMetrics + " " + path + " --step-time 0.1 --initial 0 --target 0").code, 1);        // zero step
  EXPECT_EQ(run(kMetrics + " " + path + " --step-time 0.1 --initial 0 --target 1 --value-column v").code, 1);
  EXPECT_EQ(run(kMetrics + " /nonexistent.csv --step-time 0.1 --initial 0 --target 1").code, 1);
  const std::string bad = writeFile("aic_bad.csv", "time,value\n0,0\n0.1,abc\n");
  EXPECT_EQ(run(kMetrics + " " + bad + " --step-time 0 --initial 0 --target 1").code, 1);
}

TEST(AicPredict, OneJsonLinePerCandidateAndErrorsPerLine)
{
  const std::string in = writeFile("predict_in.txt", "tau=0.03 var_y=[2,1e5,1e5,1e5] plant.time_constant=0.05\n"
                                                     "tau=0.03 var_y=[2,1e5,1e5,1e5] k_a=20 plant.time_constant=0.05 "
                                                     "plant.delay=0.12\n"
                                                     "k_a=-1\n"
                                                     "plant.gain=0\n"
                                                     "plant.nonsense=1\n"
                                                     "\n");
  const Result r = run(std::string(AIC_PREDICT_BIN) + " " + kData + "/../../config/thesis_standard.yaml < " + in);
  ASSERT_EQ(r.code, 0) << r.out;
  std::vector<std::string> lines;
  std::size_t start = 0;
  for (std::size_t i = 0; i < r.out.size(); ++i)
  {
    if (r.out[i] == '\n')
    {
      lines.push_back(r.out.substr(start, i - start));
      start = i + 1;
    }
  }
  ASSERT_EQ(lines.size(), 6u) << r.out;
  // Without latency the loop is stable and settles; with the simulated Jackal's 0.12 s it is not.
  EXPECT_NE(lines[0].find("\"stable\": true"), std::string::npos) << lines[0];
  EXPECT_EQ(lines[0].find("\"settling\": null"), std::string::npos) << lines[0];
  EXPECT_NE(lines[1].find("\"stable\": false"), std::string::npos) << lines[1];
  EXPECT_NE(lines[1].find("\"settling\": null"), std::string::npos) << lines[1];
  EXPECT_NE(lines[2].find("\"ok\": false"), std::string::npos) << lines[2];
  EXPECT_NE(lines[2].find("k_a"), std::string::npos) << lines[2];
  EXPECT_NE(lines[3].find("plant gain"), std::string::npos) << lines[3];
  EXPECT_NE(lines[4].find("unknown plant key"), std::string::npos) << lines[4];
  EXPECT_EQ(lines[5], "{}");
  // Bad arguments.
  EXPECT_EQ(run(std::string(AIC_PREDICT_BIN)).code, 2);
  EXPECT_EQ(run(std::string(AIC_PREDICT_BIN) + " /nonexistent.yaml < /dev/null").code, 1);
  EXPECT_EQ(run(std::string(AIC_PREDICT_BIN) + " x.yaml --duration -1").code, 2);
}

TEST(AicParams, GeneratesAndChecks)
{
  const std::string bin = AIC_PARAMS_BIN;
  EXPECT_EQ(run(bin).code, 2);  // exactly one output required
  EXPECT_EQ(run(bin + " --cfg --yaml").code, 2);
  EXPECT_EQ(run(bin + " --help").code, 0);
  const Result cfg = run(bin + " --cfg");
  ASSERT_EQ(cfg.code, 0) << cfg.out;
  EXPECT_NE(cfg.out.find("gen.generate(PACKAGE, \"jackal_aic_node\", \"AIC\")"), std::string::npos);
  const Result ok = run(bin + " --check " + std::string(SOURCE_DIR) + "/config/default.yaml");
  EXPECT_EQ(ok.code, 0) << ok.out;
  const Result bad = run(bin + " --check " + writeFile("params_bad.yaml", "tau: -1\nk_a: fast\nsensor_timout: 1\n"));
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.out.find("unknown key 'sensor_timout'"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("key 'k_a' must be a number"), std::string::npos) << bad.out;

  // --yaml --config: every key as the node reads the files in order; a bad file is an error
  // naming the key, not a listing; --config without --yaml is a bad argument.
  const std::string src(SOURCE_DIR);
  const Result eff =
      run(bin + " --yaml --config " + src + "/config/default.yaml --config " + src + "/config/robot.yaml");
  ASSERT_EQ(eff.code, 0) << eff.out;
  // robot.yaml's reference_delay (the later file wins), as robot.yaml spells it.
  const std::string robot_delay = yamlScalar(src + "/config/robot.yaml", "reference_delay");
  ASSERT_FALSE(robot_delay.empty());
  EXPECT_NE(eff.out.find("\nreference_delay: " + robot_delay + "\n"), std::string::npos) << eff.out;
  const Result base = run(bin + " --yaml --config " + src + "/config/default.yaml");
  EXPECT_EQ(base.out.find("\nreference_delay: " + robot_delay + "\n"), std::string::npos) << "default.yaml alone has "
                                                                                             "robot.yaml's "
                                                                                             "reference_delay: the "
                                                                                             "check above shows "
                                                                                             "nothing";
  EXPECT_NE(eff.out.find("\nleft_joints: [front_left_wheel, rear_left_wheel]\n"), std::string::npos);
  const Result bad_config = run(bin + " --yaml --config " + writeFile("params_bad_tau.yaml", "tau: -1\n"));
  EXPECT_EQ(bad_config.code, 1);
  EXPECT_NE(bad_config.out.find("tau"), std::string::npos) << bad_config.out;
  EXPECT_EQ(bad_config.out.find("k_mu:"), std::string::npos) << "printed a listing for a bad file";
  EXPECT_EQ(run(bin + " --yaml --config /nonexistent.yaml").code, 1);
  EXPECT_EQ(run(bin + " --markdown --config " + src + "/config/default.yaml").code, 2);

  // --check of an overlay (no joint lists) is done over config/default.yaml + config/robot.yaml,
  // as the robot loads it; --config names other bases; a comment-only file is one clear error.
  const Result overlay = run(bin + " --check " + src + "/config/unbiased.yaml");
  EXPECT_EQ(overlay.code, 0) << overlay.out;
  EXPECT_NE(overlay.out.find("an overlay (no joint lists): checked over config/default.yaml + config/robot.yaml"),
            std::string::npos)
      << overlay.out;
  const Result over_bases =
      run(bin + " --check " + src + "/config/goal_model.yaml --config " + src + "/config/default.yaml");
  EXPECT_EQ(over_bases.code, 0) << over_bases.out;
  EXPECT_EQ(over_bases.out.find("an overlay"), std::string::npos) << over_bases.out;
  const Result comments = run(bin + " --check " + writeFile("params_comments.yaml", "# only a comment\n"));
  EXPECT_EQ(comments.code, 1);
  EXPECT_NE(comments.out.find("no parameters (the file is empty or holds only comments)"), std::string::npos)
      << comments.out;
  EXPECT_EQ(comments.out.find("must be"), std::string::npos) << "one line, not one per key: " << comments.out;
  const Result empty_config = run(bin + " --yaml --config " + writeFile("params_comments2.yaml", "# x\n"));
  EXPECT_EQ(empty_config.code, 1);
  EXPECT_NE(empty_config.out.find("no parameters"), std::string::npos) << empty_config.out;
  // A relative path not found from the working directory is the package's.
  const Result relative = run("cd / && JACKAL_AIC_SHARE=" + src + " " + bin + " --check config/default.yaml");
  EXPECT_EQ(relative.code, 0) << relative.out;
  EXPECT_EQ(run("cd / && JACKAL_AIC_SHARE=" + src + " " + bin + " --check config/nonexistent.yaml").code, 1);
}

TEST(CommandLines, HelpExitsZeroAndBadArgumentsTwo)
{
  // One convention for every C++ tool (Boost.program_options, tools/include/jackal_tools/cli.hpp).
  for (const std::string& bin : { kAnalyze, kMetrics, std::string(AIC_PREDICT_BIN), std::string(AIC_PARAMS_BIN),
                                  std::string(AIC_TRACK_METRICS_BIN) })
  {
    EXPECT_EQ(run(bin + " --help").code, 0) << bin;
    EXPECT_EQ(run(bin + " --no-such-option").code, 2) << bin;
  }
  // A malformed override is a bad argument.
  EXPECT_EQ(run(kAnalyze + " " + kData + "/thesis_standard.yaml --no-scan --set tau").code, 2);
  EXPECT_EQ(run(kAnalyze + " " + kData + "/thesis_standard.yaml --no-scan --set tau=0.01 --set k_a=4").code, 0);
}

TEST(CommandLines, NumbersListsAndPositionals)
{
  // Long options only: "-0.5" is a value, not an option; lists are comma-separated; every
  // number must be finite; a missing positional argument is named.
  const std::string config = kData + "/thesis_standard.yaml";
  EXPECT_EQ(run(kAnalyze + " " + config + " --no-scan --rates 50,100 --target -0.5").code, 0);
  Result r = run(kAnalyze + " " + config + " --no-scan --target nan");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("not a finite number"), std::string::npos) << r.out;
  r = run(kAnalyze + " " + config + " --no-scan --rates 50,,100");
  EXPECT_EQ(r.code, 2) << r.out;
  r = run(kAnalyze + " " + config + " --no-scan --rates 50,inf");
  EXPECT_EQ(r.code, 2) << r.out;
  r = run(kAnalyze + " --no-scan");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("missing argument CONFIG"), std::string::npos) << r.out;
  r = run(std::string(AIC_PARAMS_BIN) + " --cfg --yaml");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("exactly one of"), std::string::npos) << r.out;
  r = run(std::string(CLOSED_LOOP_RUN_BIN) + " --controller open --square 0.1 --hold 1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--square takes exactly 2 numbers"), std::string::npos) << r.out;
}

TEST(ClosedLoopRun, ControllerAndChannelAreChecked)
{
  const std::string bin = CLOSED_LOOP_RUN_BIN;
  Result r = run(bin + " --controller open --step 0.3 --channel sideways");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("channel"), std::string::npos) << r.out;
  r = run(bin + " --controller pid --step 0.3");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("controller"), std::string::npos) << r.out;
  r = run(bin + " --controller aic --aic-config " + std::string(SOURCE_DIR) +
          "/config/default.yaml --step 0.3 --fault 'gyro melt 1'");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--fault 'gyro melt 1'"), std::string::npos) << r.out;
  r = run(bin + " --controller aic --aic-config " + std::string(SOURCE_DIR) +
          "/config/default.yaml --step 0.3 --aic-set belief_schedule=sometimes");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("belief_schedule"), std::string::npos) << r.out;
  // An angular open-loop step reports its metrics on the yaw rate.
  r = run(bin + " --controller open --step 0.5 --channel angular --hold 1");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\"channel\": \"angular\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"target\": 0.5"), std::string::npos) << r.out;
}

TEST(ClosedLoopRun, CombinedStepReportsBothChannels)
{
  const std::string bin = CLOSED_LOOP_RUN_BIN;
  // --turn W: (V, W) at once; the linear metrics in "segments", the yaw rate's in "angular_segments".
  Result r = run(bin + " --controller open --step 0.3 --turn 0.4 --hold 1");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto angular = r.out.find("\"angular_segments\": [{");
  ASSERT_NE(angular, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"target\": 0.3"), std::string::npos) << r.out;
  EXPECT_GT(r.out.find("\"target\": 0.4"), angular) << r.out;
  r = run(bin + " --controller open --square 0.1 0.5 --turn 0.4");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--turn needs --step"), std::string::npos) << r.out;
  r = run(bin + " --controller open --step 0.3 --turn 0.4 --channel angular");
  EXPECT_EQ(r.code, 2) << r.out;
  r = run(bin + " --controller open --step 0.3 --turn nan");
  EXPECT_EQ(r.code, 2) << r.out;
}

TEST(ClosedLoopRun, CsvProfileReportsTrackingAndPath)
{
  const std::string bin = CLOSED_LOOP_RUN_BIN;
  // A straight run at 0.4 m/s, then an arc: the tracking of both channels and the path drift.
  const std::string profile = writeFile("track_profile.csv", "t,vx,wz\n0,0.4,0\n1.0,0.4,0.5\n2.0,0,0\n");
  const std::string trace = std::string(::testing::TempDir()) + "track_trace.csv";
  Result r = run(bin + " --controller stock --profile " + profile + " --csv " + trace);
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* key : { "\"profile\": \"track_profile\"", "\"duration\": 2,",
                           "\"tracking\": {\"truth\": {\"vx\": {\"rms\": ", "\"odometry\": {\"vx\"",
                           "\"path\": {\"final_position_error\": ", "\"segments\": []" })
  {
    EXPECT_NE(r.out.find(key), std::string::npos) << key << "\n" << r.out;
  }
  std::ifstream f(trace);
  std::string header;
  std::getline(f, header);
  EXPECT_NE(header.find(",x,y,heading,x_ideal,y_ideal,heading_ideal"), std::string::npos) << header;
  // The trace's pose and the profile through aic_track_metrics: the same path drift.
  const std::string metrics = AIC_TRACK_METRICS_BIN;
  r = run(metrics + " --profile " + profile + " --trace " + trace);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\"path\": {\"final_position_error\": "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"tracking\": {}"), std::string::npos) << r.out;  // no S_vx, S_wz columns
  // --segments: the step metrics of the transitions, both channels.
  r = run(bin + " --controller open --profile " + profile + " --segments");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\"angular_segments\": [{"), std::string::npos) << r.out;
  // Bad profiles: exit 1 with the file and line; bad combinations: exit 2.
  const std::string bad = writeFile("track_bad.csv", "t,vx,wz\n0,0.4,0\n1.0,nan,0\n2,0,0\n");
  r = run(bin + " --controller stock --profile " + bad);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("track_bad.csv line 3: vx 'nan' is not finite"), std::string::npos) << r.out;
  const std::string back = writeFile("track_back.csv", "0,0.4,0\n1.0,0.1,0\n0.5,0,0\n");
  r = run(bin + " --controller stock --profile " + back);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("line 3: t must increase"), std::string::npos) << r.out;
  EXPECT_EQ(run(bin + " --controller stock --profile /nonexistent.csv").code, 1);
  EXPECT_EQ(run(bin + " --controller stock --profile " + profile + " --step 0.5").code, 2);
  EXPECT_EQ(run(bin + " --controller stock --step 0.5 --segments").code, 2);
}

/// The rows of a CSV file as maps from column name to cell.
std::vector<std::map<std::string, std::string>> readCsv(const std::string& path, std::vector<std::string>* header)
{
  std::ifstream f(path);
  std::string line;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& text) {
    std::vector<std::string> cells;
    std::stringstream ss(text);
    std::string cell;
    while (std::getline(ss, cell, ','))
    {
      cells.push_back(cell);
    }
    if (!text.empty() && text.back() == ',')
    {
      cells.emplace_back();
    }
    return cells;
  };
  if (!std::getline(f, line))
  {
    return rows;
  }
  *header = split(line);
  while (std::getline(f, line))
  {
    const std::vector<std::string> cells = split(line);
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header->size() && i < cells.size(); ++i)
    {
      row[(*header)[i]] = cells[i];
    }
    rows.push_back(row);
  }
  return rows;
}

TEST(ClosedLoopRun, CsvTraceHoldsTheInference)
{
  const std::string bin = CLOSED_LOOP_RUN_BIN;
  const std::string trace = std::string(::testing::TempDir()) + "inference_trace.csv";
  // The default configuration (embedding order 2) on the 0.5 m/s + 0.5 rad/s arc.
  Result r = run(bin + " --controller aic --aic-config " + SOURCE_DIR + "/config/default.yaml --step 0.5 --turn 0.5" +
                 " --hold 2 --csv " + trace);
  ASSERT_EQ(r.code, 0) << r.out;
  std::vector<std::string> header;
  const auto rows = readCsv(trace, &header);
  ASSERT_GT(rows.size(), 100u);
  int eps_mu = 0, eps_y = 0, mu = 0;
  for (const std::string& h : header)
  {
    eps_mu += h.rfind("eps_mu", 0) == 0;
    eps_y += h.rfind("eps_y", 0) == 0;
    mu += h.rfind("mu", 0) == 0;
  }
  EXPECT_EQ(mu, 3 * 3);
  EXPECT_EQ(eps_y, 5 * 3);
  EXPECT_EQ(eps_mu, 3 * 3);
  for (const char* column : { "F[-]", "F_sensory[-]", "F_prior[-]", "a_L[rad/s]", "a_ff_R[rad/s]", "goal_x_dot[m/s]",
                              "Pi_y0_gyro_z[1/(rad/s)^2]", "Pi_y0_accel_y[1/(m/s^2)^2]", "mu0_theta_dot[rad/s]",
                              "eps_y2_gyro_z[rad/s^3]", "eps_mu0_x_dot[m/s^2]", "mu2_x_dot[m/s^3]" })
  {
    EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  }
  int started = 0;
  double peak = 0.0;
  for (const auto& row : rows)
  {
    if (row.at("F[-]").empty())
    {
      EXPECT_EQ(started, 0) << "the inference stops after the controller started, t = " << row.at("t");
      continue;
    }
    ++started;
    const double f = std::stod(row.at("F[-]"));
    const double parts = std::stod(row.at("F_sensory[-]")) + std::stod(row.at("F_prior[-]"));
    ASSERT_TRUE(std::isfinite(f) && f >= 0.0) << row.at("t");
    EXPECT_NEAR(f, parts, 1e-5 * std::max(1.0, f)) << row.at("t");  // 6 significant digits each
    EXPECT_EQ(row.at("mu0_theta_dot[rad/s]"), row.at("belief_yaw")) << row.at("t");
    peak = std::max(peak, f);
  }
  EXPECT_GT(started, 100);
  EXPECT_GT(peak, 0.0);  // the step's transient has a free energy to descend
  // The stock controller has no inference to trace.
  r = run(bin + " --controller stock --step 0.5 --hold 1 --csv " + trace);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(readCsv(trace, &header).size() > 10u);
  EXPECT_EQ(std::find(header.begin(), header.end(), "F[-]"), header.end());
}

TEST(ClosedLoopRun, CsvTraceHoldsTheFaultMonitorsTest)
{
  // The goal model (belief_model goal over the default configuration: its fault monitor tests the
  // parity residual against fdi_threshold; the robot model's innovation test has no threshold key)
  // on the 0.5 m/s + 0.5 rad/s arc, a 0.5 rad/s gyro bias from 3 s
  // (profile time 2 s): fdi_statistic stays below fdi_threshold (0.06) before the fault and goes
  // above it after; the residual is the gyro's disagreement, about the bias. The stock controller
  // has no fault monitor: the columns are empty.
  const std::string bin = CLOSED_LOOP_RUN_BIN;
  const std::string trace = std::string(::testing::TempDir()) + "fdi_trace.csv";
  Result r = run(bin + " --controller aic --aic-config " + SOURCE_DIR +
                 "/config/default.yaml --aic-set belief_model=goal --step 0.5 --turn 0.5 --hold 3 --noise --fault "
                 "'gyro bias 0.5 3' --csv " +
                 trace);
  ASSERT_EQ(r.code, 0) << r.out;
  std::vector<std::string> header;
  const auto rows = readCsv(trace, &header);
  ASSERT_GT(rows.size(), 100u);
  double before = 0.0, after = 0.0, residual_after = 0.0;
  int tested = 0;
  for (const auto& row : rows)
  {
    if (row.at("fdi_statistic").empty())
    {
      continue;
    }
    ++tested;
    const double t = std::stod(row.at("t"));
    const double s = std::stod(row.at("fdi_statistic"));
    ASSERT_TRUE(std::isfinite(s) && s >= 0.0) << t;
    if (t > 0.5 && t < 1.9)
    {
      before = std::max(before, s);
    }
    if (t > 2.1)
    {
      after = std::max(after, s);
      residual_after = std::max(residual_after, std::stod(row.at("fdi_residual")));
    }
  }
  EXPECT_GT(tested, 100);
  EXPECT_LT(before, 0.06);
  EXPECT_GT(after, 0.06);
  EXPECT_NEAR(residual_after, 0.5, 0.1);
  r = run(bin + " --controller stock --step 0.5 --hold 1 --csv " + trace);
  ASSERT_EQ(r.code, 0) << r.out;
  for (const auto& row : readCsv(trace, &header))
  {
    EXPECT_TRUE(row.at("fdi_statistic").empty() && row.at("fdi_residual").empty()) << row.at("t");
  }
}

TEST(AicTrackMetrics, SignalsPoseAndBadInput)
{
  const std::string bin = AIC_TRACK_METRICS_BIN;
  const std::string profile = writeFile("tm_profile.csv", "t,vx,wz\n0,0.5,0\n2,0,0\n");
  Result r = run(bin + " --profile " + profile + " --print-profile");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\"duration\": 2, \"points\": [[0, 0.5, 0]]"), std::string::npos) << r.out;
  // odom 0.1 m/s low throughout, belief exact but missing at one sample; a pose that holds the line.
  std::string text = "t,odom_vx,odom_wz,belief_vx,belief_wz,x,y,heading\n";
  for (int k = -5; k <= 100; ++k)
  {
    const double t = 0.02 * k;
    const double v = t >= 0.0 ? 0.5 : 0.0;
    const double x = t >= 0.0 ? 0.5 * t : 0.0;
    text += std::to_string(t) + "," + std::to_string(v - 0.1) + ",0," + (k == 50 ? std::string(",") : "0.5,0") + "," +
            std::to_string(x) + ",0.05,0\n";
  }
  const std::string trace = writeFile("tm_trace.csv", text);
  const std::string ideal = std::string(::testing::TempDir()) + "tm_ideal.csv";
  r = run(bin + " --profile " + profile + " --trace " + trace + " --ideal-csv " + ideal);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\"odom\": {\"vx\": {\"rms\": 0.1, \"max\": 0.1}"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"belief\": {\"vx\": {\"rms\": 0, \"max\": 0}, \"wz\": {\"rms\": 0, \"max\": 0}, "
                       "\"samples\": 100}"),
            std::string::npos)
      << r.out;
  EXPECT_NEAR(numberAfter(r.out, "\"final_position_error\": "), 0.0, 1e-9) << r.out;  // starts at y = 0.05 too
  EXPECT_NEAR(numberAfter(r.out, "\"ideal_length\": "), 1.0, 1e-9) << r.out;
  std::ifstream f(ideal);
  std::string line;
  std::getline(f, line);
  EXPECT_EQ(line, "t,x,y,heading");
  // Bad input: exit 1 naming the problem; bad arguments: exit 2.
  const std::string nan_trace = writeFile("tm_nan.csv", "t,odom_vx,odom_wz\n0,0.5,0\n0.02,nan,0\n");
  r = run(bin + " --profile " + profile + " --trace " + nan_trace);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("odom_vx 'nan' is not finite"), std::string::npos) << r.out;
  const std::string no_signal = writeFile("tm_none.csv", "t,speed\n0,0.5\n");
  r = run(bin + " --profile " + profile + " --trace " + no_signal);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("no S_vx, S_wz column pair"), std::string::npos) << r.out;
  const std::string empty_signal = writeFile("tm_empty.csv", "t,odom_vx,odom_wz,x,y,heading\n0,,,0,0,0\n1,,,0.5,0,0\n");
  r = run(bin + " --profile " + profile + " --trace " + empty_signal);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\"tracking\": {\"odom\": null}"), std::string::npos) << r.out;
  const std::string late = writeFile("tm_late.csv", "t,odom_vx,odom_wz\n3,0.5,0\n4,0.5,0\n");
  EXPECT_EQ(run(bin + " --profile " + profile + " --trace " + late).code, 1);
  const std::string one_row = writeFile("tm_one.csv", "t,vx,wz\n0,0.5,0\n");
  r = run(bin + " --profile " + one_row + " --print-profile");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("at least two rows"), std::string::npos) << r.out;
  EXPECT_EQ(run(bin + " --profile " + profile).code, 2);
  EXPECT_EQ(run(bin + " --profile " + profile + " --trace " + trace + " --print-profile").code, 2);
  EXPECT_EQ(run(bin + " --trace " + trace).code, 2);
  // The latency floor: 0.5 m/s held from 0 s, the servo 0.1 s late: 0.5 sqrt(100 / 2001) both ways.
  r = run(bin + " --profile " + profile + " --floor-latency 0.1");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NEAR(numberAfter(r.out, "\"hold\": {\"vx\": {\"rms\": "), 0.5 * std::sqrt(100.0 / 2001.0), 1e-6) << r.out;
  EXPECT_NEAR(numberAfter(r.out, "\"predict\": {\"vx\": {\"rms\": "), 0.5 * std::sqrt(100.0 / 2001.0), 1e-6) << r.out;
  EXPECT_EQ(run(bin + " --profile " + profile + " --floor-latency -0.1").code, 2);
  EXPECT_EQ(run(bin + " --profile " + profile + " --floor-latency nan").code, 2);
  EXPECT_EQ(run(bin + " --profile " + profile + " --floor-latency 0.1 --floor-accel-linear -1").code, 2);
  EXPECT_EQ(run(bin + " --profile " + profile + " --floor-latency 0.1 --trace " + trace).code, 2);
  r = run(bin + " --profile " + profile + " --floor-latency 20");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("latency must be finite and in [0, 10] s"), std::string::npos) << r.out;
}

TEST(AicTiming, PrintsOneRowPerLoopAndRate)
{
  // Figures are machine-dependent (doc/jackal_aic_node.md quotes a run): check the table, not the timing.
  const std::string bin = AIC_TIMING_BIN;
  const Result r = run(bin + " --duration 0.3 --rates 200,500 --config " + std::string(SOURCE_DIR) +
                       "/config/default.yaml --set tau=0.02");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("integrator exact"), std::string::npos) << r.out;
  for (const char* row :
       { "| belief |      200 |", "| bare   |      200 |", "| belief |      500 |", "| bare   |      500 |" })
  {
    EXPECT_NE(r.out.find(row), std::string::npos) << row << "\n" << r.out;
  }
  EXPECT_EQ(run(bin + " --duration 0").code, 2);
  EXPECT_EQ(run(bin + " --rates 0").code, 2);
  EXPECT_EQ(run(bin + " --priority 100").code, 2);
  EXPECT_EQ(run(bin + " --set tau=0.01").code, 2);  // an override needs a configuration
  EXPECT_EQ(run(bin + " --duration 0.1 --config " + writeFile("timing_bad.yaml", "tau: -1\n")).code, 1);
}
