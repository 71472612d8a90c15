/**
 * \file test_soak.cpp
 * \brief The soak's short form (aic_soak, tools/src/aic_soak.cpp; doc/tools.md, 'Soak'): six
 *        simulated minutes of random planner and joystick streams with a fault scenario every
 *        15 s and an operation around the node (clock step back, simulator restart, driver pause,
 *        node respawn) every 20 s on average, seeded; every check of the full 8-hour form must
 *        pass. The random-driving form (no faults, no operations, noisy sensors): the learned
 *        wheel separation's 5-minute means stay within 2 % of its median. Also the tool's
 *        refusal of bad arguments.
 */
#include <gtest/gtest.h>

#include "jackal_test/run_command.hpp"

#include <cstdio>
#include <string>

namespace
{
using Result = jackal_test::CommandResult;
constexpr auto* run = &jackal_test::runCommand;

const std::string kSoak = std::string("JACKAL_AIC_SHARE=") + SOURCE_DIR + " " + AIC_SOAK_BIN + " --profile-dir " +
                          SOURCE_DIR + "/test/data/soak_profiles";

TEST(Soak, ShortFormPassesEveryCheck)
{
  const Result r = run(kSoak + " --hours 0.1 --seed 7 --fault-every 15 --operation-every 20");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("Verdict: PASS"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| non-finite values | 0 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| runaway resets | 0 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Operations after which the controller never ran again: 0."), std::string::npos) << r.out;
  for (const char* kind : { "| clock_back | ", "| plant_restart | ", "| driver_pause | ", "| node_restart | " })
  {
    const std::size_t at = r.out.find(kind);
    ASSERT_NE(at, std::string::npos) << kind << r.out;
    EXPECT_NE(r.out.compare(at + std::string(kind).size(), 2, "0 "), 0) << kind << " never happened\n" << r.out;
  }
}

// The learned b_hat's drift bound in random driving, on a 15-minute form (doc/results/soak_learning.md
// has the 30-minute figures): its 5-minute means within 2 % of its median (the bound itself, not
// today's figure), while single samples follow the operating point's effective separation further
// (reported, not judged).
TEST(Soak, RandomDrivingKeepsTheLearnedSeparationsFiveMinuteMeansWithinTwoPercent)
{
  const Result r = run(kSoak + " --hours 0.25 --seed 7 --noise --fault-every 0 --operation-every 0");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("| fault scenarios injected | 0 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| operations | 0 |"), std::string::npos) << r.out;
  const std::size_t at = r.out.find("| b_hat's means over 5-minute windows (3) | ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::size_t eol = r.out.find('\n', at);
  EXPECT_NE(r.out.substr(at, eol - at).find("within 2 % of the median: yes"), std::string::npos) << r.out;
}

TEST(Soak, RefusesBadArguments)
{
  EXPECT_EQ(run(kSoak + " --hours 0").code, 2);
  EXPECT_EQ(run(kSoak + " --hours 0.01 --fault-every -1").code, 2);
  EXPECT_EQ(run(kSoak + " --hours 0.01 --operation-every nan").code, 2);
  EXPECT_EQ(run(std::string(AIC_SOAK_BIN) + " --hours 0.01 --profile-dir /nonexistent").code, 1);
}
}  // namespace
