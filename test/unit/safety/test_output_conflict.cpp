/**
 * \file test_output_conflict.cpp
 * \brief gtest (no roscore) of one publisher per command topic: the OutputConflict state
 *        machine (include/jackal_aic/safety/output_conflict.hpp) and the Supervisor's kBlocked state
 *        (doc/jackal_aic_node.md, 'One publisher per command topic'). The ControlLoop's side
 *        (nothing published while blocked, the bumpless restart) is in test_control_loop.cpp.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "jackal_aic/safety/output_conflict.hpp"
#include "jackal_aic/loop/supervisor.hpp"

namespace jackal_aic
{
namespace
{
using Event = safety::OutputConflict::Event;

TEST(OutputConflict, RefusesEmptyNames)
{
  EXPECT_THROW(safety::OutputConflict("", "/jackal_AIC"), std::invalid_argument);
  EXPECT_THROW(safety::OutputConflict("/cmd_drive", ""), std::invalid_argument);
}

TEST(OutputConflict, ItselfAloneIsNoConflict)
{
  safety::OutputConflict c("/cmd_drive", "/jackal_AIC");
  EXPECT_EQ(c.update({}, 0.0), Event::kNone);
  EXPECT_EQ(c.update({ "/jackal_AIC" }, 0.1), Event::kNone);
  EXPECT_EQ(c.update({ "/jackal_AIC", "", "/jackal_AIC" }, 0.2), Event::kNone);
  EXPECT_FALSE(c.conflicted());
  EXPECT_EQ(c.othersText(), "none");
  EXPECT_TRUE(std::isnan(c.since()));
  EXPECT_EQ(c.conflicts(), 0u);
  EXPECT_EQ(c.message(Event::kNone), "");
}

TEST(OutputConflict, StartsChangesAndEnds)
{
  safety::OutputConflict c("/jackal_velocity_controller/cmd_vel", "/jackal_AIC");
  // Another publisher appears: one kStarted naming it, then nothing while it stays.
  EXPECT_EQ(c.update({ "/jackal_AIC", "/twist_mux" }, 1.0), Event::kStarted);
  EXPECT_TRUE(c.conflicted());
  EXPECT_EQ(c.others(), std::vector<std::string>{ "/twist_mux" });
  EXPECT_DOUBLE_EQ(c.since(), 1.0);
  const std::string started = c.message(Event::kStarted);
  EXPECT_NE(started.find("/twist_mux"), std::string::npos) << started;
  EXPECT_NE(started.find("/jackal_velocity_controller/cmd_vel"), std::string::npos) << started;
  EXPECT_NE(started.find("publishes nothing"), std::string::npos) << started;
  EXPECT_EQ(started.find("/jackal_AIC:"), std::string::npos) << "names itself as the other: " << started;
  EXPECT_EQ(c.update({ "/twist_mux", "/jackal_AIC" }, 1.25), Event::kNone);  // order does not matter
  EXPECT_EQ(c.update({ "/twist_mux" }, 1.5), Event::kNone);                  // nor whether it lists us
  // A second one joins: kChanged, both named, sorted, the start time kept.
  EXPECT_EQ(c.update({ "/twist_mux", "/jackal_AIC", "/a_relay", "/twist_mux" }, 2.0), Event::kChanged);
  EXPECT_EQ(c.othersText(), "/a_relay, /twist_mux");
  EXPECT_DOUBLE_EQ(c.since(), 1.0);
  EXPECT_EQ(c.conflicts(), 1u);
  // Both leave: kEnded, driving resumes.
  EXPECT_EQ(c.update({ "/jackal_AIC" }, 3.0), Event::kEnded);
  EXPECT_FALSE(c.conflicted());
  EXPECT_NE(c.message(Event::kEnded).find("publishes its commands again"), std::string::npos);
  // A new conflict is counted again.
  EXPECT_EQ(c.update({ "/jackal_node" }, 4.0), Event::kStarted);
  EXPECT_EQ(c.conflicts(), 2u);
  EXPECT_DOUBLE_EQ(c.since(), 4.0);
}

TEST(OutputConflict, AFailedQueryKeepsTheState)
{
  safety::OutputConflict c("/cmd_drive", "/jackal_AIC");
  EXPECT_EQ(c.update({ "/jackal_node" }, 0.0), Event::kStarted);
  c.queryFailed();
  EXPECT_TRUE(c.conflicted());
  EXPECT_EQ(c.queryFailures(), 1u);
  EXPECT_EQ(c.update({}, 1.0), Event::kEnded);
  c.queryFailed();
  EXPECT_FALSE(c.conflicted());
  EXPECT_EQ(c.queryFailures(), 2u);
}

TEST(OutputConflict, EventNames)
{
  EXPECT_STREQ(safety::toString(Event::kNone), "none");
  EXPECT_STREQ(safety::toString(Event::kStarted), "started");
  EXPECT_STREQ(safety::toString(Event::kChanged), "changed");
  EXPECT_STREQ(safety::toString(Event::kEnded), "ended");
}

class FakeClock : public loop::Clock
{
public:
  double now() const override { return t; }
  double t = 0.0;  ///< [s]
};

TEST(SupervisorBlocked, BlockedOutranksEveryOtherStateAndReleases)
{
  FakeClock clock;
  params::NodeParams p;
  p.left_joints = { "l" };
  p.right_joints = { "r" };
  loop::Supervisor s(p, clock);
  const double sp[6] = { 0.5, 0, 0, 0, 0, 0 };
  for (int i = 0; i < p.aic.numOrders(); ++i)
  {
    clock.t += 0.02;
    s.setPoint(sp);
    s.sampleAccepted(base::Vector2(1.0, 1.0));
  }
  ASSERT_TRUE(s.update().activate());
  EXPECT_TRUE(s.active());

  s.outputBlocked(true, "another node publishes on /cmd_drive: /jackal_node; publishing nothing there");
  loop::Supervisor::Transition t = s.update();
  EXPECT_TRUE(t.deactivate());
  EXPECT_FALSE(t.warn());  // the node logs the conflict itself (one ERROR)
  EXPECT_EQ(s.state(), loop::NodeState::kBlocked);
  EXPECT_STREQ(loop::toString(s.state()), "blocked");
  EXPECT_NE(s.reason().find("/jackal_node"), std::string::npos);
  EXPECT_TRUE(s.blocked());
  EXPECT_EQ(s.blockedEvents(), 1u);
  // Stale sensors and set point, an MCU stop: still blocked (nothing is published anyway).
  clock.t += 1.0;
  s.mcuStatus(false, false, false);
  EXPECT_FALSE(s.update().changed);
  EXPECT_EQ(s.state(), loop::NodeState::kBlocked);
  // A different other publisher: the reason follows, no new entry.
  s.outputBlocked(true, "another node publishes on /cmd_drive: /a, /jackal_node; publishing nothing there");
  EXPECT_FALSE(s.update().changed);
  EXPECT_NE(s.reason().find("/a, /jackal_node"), std::string::npos) << s.reason();
  EXPECT_EQ(s.blockedEvents(), 1u);
  // Released: back to what the inputs say (stale here), then running on fresh inputs.
  s.outputBlocked(false);
  s.mcuStatus(true, false, false);
  EXPECT_EQ(s.update().to, loop::NodeState::kStale);
  EXPECT_FALSE(s.blocked());
  for (int i = 0; i < p.aic.numOrders() + 1; ++i)
  {
    clock.t += 0.02;
    s.setPoint(sp);
    s.sampleAccepted(base::Vector2(1.0, 1.0));
    s.update();
  }
  EXPECT_TRUE(s.active());
}

}  // namespace
}  // namespace jackal_aic
