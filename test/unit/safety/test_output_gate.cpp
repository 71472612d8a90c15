/**
 * \file test_output_gate.cpp
 * \brief gtests of the jackal_AIC node's output gate (jackal_aic/safety/output_gate.hpp): the rule
 *        behind ~enable_output, without a roscore.
 */
#include <gtest/gtest.h>

#include "jackal_aic/safety/output_gate.hpp"

namespace jackal_aic
{
namespace
{
TEST(OutputGate, StartsEnabledAndAdmitsEveryCommand)
{
  safety::OutputGate gate;
  EXPECT_TRUE(gate.enabled());
  for (int i = 0; i < 5; ++i)
  {
    EXPECT_TRUE(gate.admit());
  }
  EXPECT_EQ(gate.suppressed(), 0u);
  EXPECT_EQ(gate.switches(), 0u);
}

TEST(OutputGate, DisabledDropsAndCountsEveryCommand)
{
  safety::OutputGate gate;
  const safety::OutputGate::Change c = gate.set(false);
  EXPECT_TRUE(c.changed);
  EXPECT_FALSE(c.enabled);
  EXPECT_FALSE(c.restart);  // disabling never restarts the controller
  for (int i = 0; i < 3; ++i)
  {
    EXPECT_FALSE(gate.admit());
  }
  EXPECT_EQ(gate.suppressed(), 3u);
}

TEST(OutputGate, ReEnablingRestartsOnceFromTheMeasuredState)
{
  safety::OutputGate gate;
  gate.set(false);
  const safety::OutputGate::Change on = gate.set(true);
  EXPECT_TRUE(on.changed);
  EXPECT_TRUE(on.enabled);
  EXPECT_TRUE(on.restart);
  EXPECT_TRUE(gate.admit());
  const safety::OutputGate::Change again = gate.set(true);  // a repeated request: nothing to do
  EXPECT_FALSE(again.changed);
  EXPECT_FALSE(again.restart);
  EXPECT_EQ(gate.switches(), 2u);
}

TEST(OutputGate, RepeatedDisableChangesNothing)
{
  safety::OutputGate gate;
  gate.set(false);
  const safety::OutputGate::Change c = gate.set(false);
  EXPECT_FALSE(c.changed);
  EXPECT_FALSE(c.restart);
  EXPECT_FALSE(gate.enabled());
  EXPECT_EQ(gate.switches(), 1u);
}

}  // namespace
}  // namespace jackal_aic
