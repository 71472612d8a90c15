#!/usr/bin/env python3
"""Python unit test (no roscore): the ROS fuzz's generator and verdict
(jackal_aic_tools.robustness.ros_fuzz, scripts/aic_ros_fuzz.py): seeded and deterministic, every
kind of odd input it promises, plausible messages that are valid, messages that serialize, the
command check (jackal_aic_tools.robustness.node_watch: float32 limit, non-finite, over-limit), the
verdict and the figures' formatting.
"""
import collections
import io
import math
import os
import struct
import sys
import unittest

ROOT = os.path.realpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), ".."))
sys.path.insert(0, os.path.join(ROOT, "src"))
from jackal_aic_tools.robustness import node_watch, ros_fuzz  # noqa: E402
from jackal_aic_tools.robustness.node_watch import CommandCheck  # noqa: E402
from jackal_aic_tools.robustness.ros_fuzz import FuzzGenerator  # noqa: E402

import random  # noqa: E402

T0_NS = 1_700_000_000 * 10 ** 9  # a wall-clock-like start [ns]


def generate(seed, n, rate=1000.0):
    """n messages of FuzzGenerator(seed, rate) on a virtual clock (now = T0 + the gaps so far),
    as (now_ns, Message) pairs."""
    gen = FuzzGenerator(random.Random(seed), rate)
    t, out = 0.0, []
    for _ in range(n):
        now = T0_NS + int(t * 1e9)
        m = gen.next(now)
        out.append((now, m))
        t += m.gap
    return out, gen


def numbers(fields):
    """Every float in a message's fields (lists nested one deep included)."""
    out = []
    for v in fields.values():
        if isinstance(v, float):
            out.append(v)
        elif isinstance(v, list):
            for x in v:
                out.extend(x if isinstance(x, list) else [x])
    return [x for x in out if isinstance(x, float)]


class GeneratorTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.msgs, cls.gen = generate(1, 60000)

    def test_same_seed_same_messages_other_seed_others(self):
        a, _ = generate(7, 3000)
        b, _ = generate(7, 3000)
        c, _ = generate(8, 3000)
        key = lambda ms: [(m.kind, repr(m.fields), m.tags, m.gap) for _, m in ms]
        self.assertEqual(key(a), key(b))
        self.assertNotEqual(key(a), key(c))

    def test_every_odd_input_occurs(self):
        tags = collections.Counter(t for _, m in self.msgs for t in m.tags)
        for t in ("nan", "+inf", "-inf", "-0.0", "huge", "tiny", "zero", "stamp zero", "stamp backwards",
                  "stamp future", "stamp repeated", "stamp jitter", "joint missing", "joint duplicated",
                  "joint unknown", "length position", "length velocity", "length effort", "after silence",
                  "status drivers_active", "feedback mode -1"):
            self.assertGreater(tags[t], 0, t)
        for phase in ("plausible", "fuzz", "burst", "silence"):
            self.assertGreater(self.gen.phases[phase], 0, phase)
        kinds = collections.Counter((m.kind, bool(m.tags)) for _, m in self.msgs)
        for k in ros_fuzz.KINDS:
            self.assertGreater(kinds[(k, False)], 0, k)
            self.assertGreater(kinds[(k, True)], 0, k)

    def test_tags_say_what_is_in_the_message(self):
        for _, m in self.msgs:
            vals = numbers(m.fields)
            if "nan" in m.tags:
                self.assertTrue(any(math.isnan(x) for x in vals), m)
            if "+inf" in m.tags:
                self.assertIn(float("inf"), vals, m)
            if "-0.0" in m.tags:
                self.assertTrue(any(x == 0.0 and math.copysign(1.0, x) < 0 for x in vals), m)
            if "stamp zero" in m.tags:
                self.assertEqual(m.fields["stamp"], 0)
            if "joint unknown" not in m.tags and m.kind == "joint_states" and "joint duplicated" not in m.tags:
                self.assertTrue(set(m.fields["name"]) <= set(ros_fuzz.KNOWN_JOINTS), m)

    def test_plausible_messages_are_valid_and_stamped_now(self):
        seen = 0
        for now, m in self.msgs:
            if m.tags:
                continue
            seen += 1
            vals = numbers(m.fields)
            self.assertTrue(all(math.isfinite(x) for x in vals), m)
            if "stamp" in m.fields:
                self.assertEqual(m.fields["stamp"], now + int(m.gap * 1e9))
            if m.kind == "joint_states":
                self.assertEqual(sorted(m.fields["name"]), sorted(ros_fuzz.KNOWN_JOINTS))
                for f in ("position", "velocity", "effort"):
                    self.assertEqual(len(m.fields[f]), 4)
                self.assertTrue(all(abs(v) < 25.0 for v in m.fields["velocity"]), m)
            elif m.kind == "set_point":
                self.assertLessEqual(abs(m.fields["linear"][0]), 1.0)
                self.assertLessEqual(abs(m.fields["angular"][2]), 1.5)
            elif m.kind == "status":
                self.assertTrue(m.fields["drivers_active"])
                self.assertFalse(m.fields["stop_stopped"])
        self.assertGreater(seen, 10000)

    def test_hold_plausible_never_ends(self):
        gen = FuzzGenerator(random.Random(4), 1000.0)
        for _ in range(50):
            gen.next(T0_NS)  # somewhere in its stretches
        gen.hold_plausible(0.5, 0.0)
        t, kinds = 0.0, collections.Counter()
        for _ in range(3000):
            m = gen.next(T0_NS + int(t * 1e9))
            t += m.gap
            kinds[m.kind] += 1
            self.assertEqual(m.tags, (), m)
            if m.kind == "joint_states":
                self.assertTrue(all(abs(v - 0.5 / ros_fuzz.WHEEL_RADIUS) < 0.5 for v in m.fields["velocity"]), m)
        self.assertAlmostEqual(kinds["joint_states"] / t, ros_fuzz.PLAUSIBLE_RATE, delta=1.0)
        self.assertAlmostEqual(kinds["set_point"] / t, ros_fuzz.SET_POINT_RATE, delta=1.0)

    def test_stamps_and_float32_fields_stay_representable(self):
        for _, m in self.msgs:
            if "stamp" in m.fields:
                self.assertTrue(0 <= m.fields["stamp"] <= ros_fuzz.MAX_STAMP_NS, m)
            if m.kind == "status":
                for x in m.fields["floats"][:8]:
                    struct.pack("f", x)  # raises OverflowError beyond float32
            if m.kind == "feedback":
                self.assertTrue(-128 <= m.fields["actual_mode"] <= 127 and -128 <= m.fields["commanded_mode"] <= 127)

    def test_fuzz_stretches_at_the_rate(self):
        for rate in (200.0, 1000.0):
            msgs, _ = generate(2, 20000, rate)
            gaps = [m.gap for _, m in msgs if m.tags and "after silence" not in m.tags and m.gap > 0]
            mean = sum(gaps) / len(gaps)
            self.assertAlmostEqual(mean * rate, 1.0, delta=0.1)  # exponential gaps, mean 1 / rate
        with self.assertRaises(ValueError):
            FuzzGenerator(random.Random(1), 0.0)

    def test_messages_serialize(self):
        try:
            import genpy  # noqa: F401
            from jackal_msgs.msg import Status  # noqa: F401
        except ImportError:
            self.skipTest("ROS message modules not on the path (source the workspace)")
        for _, m in self.msgs[:20000]:
            ros_fuzz.to_ros(m.kind, m.fields).serialize(io.BytesIO())


class CheckAndVerdictTest(unittest.TestCase):

    def test_limit_is_compared_in_float32(self):
        c = CommandCheck(8.1)
        c.add([node_watch.float32(8.1), -node_watch.float32(8.1)])
        self.assertTrue(c.clean())
        c.add([8.1001, 0.0])
        c.add([float("nan"), 0.0])
        c.add([float("inf"), 0.0])
        self.assertEqual((c.commands, c.over_limit, c.non_finite), (4, 1, 2))
        self.assertAlmostEqual(c.max_abs, 8.1001)
        self.assertFalse(c.clean())

    def test_findings_kept_and_verdict(self):
        c = CommandCheck(20.0)
        for i in range(10):
            c.add([30.0 + i, 0.0], i)
        self.assertEqual(len(c.findings), CommandCheck.KEEP)
        self.assertIn("30.0", c.findings[0])
        clean = CommandCheck(20.0)
        clean.add([20.0, -20.0])
        self.assertEqual(ros_fuzz.verdict(clean, True, 100), [])
        self.assertEqual(ros_fuzz.verdict(clean, False, 100), ["the node is not running at the end"])
        self.assertIn("stopped publishing", ros_fuzz.verdict(clean, True, 0)[0])
        v = ros_fuzz.verdict(c, True, 100)
        self.assertEqual(v[0], "10 command(s) beyond +-20 rad/s")
        nf = CommandCheck(20.0)
        nf.add([float("nan"), 0.0])
        self.assertEqual(ros_fuzz.verdict(nf, True, 5)[0], "1 non-finite command(s)")

    def test_drop_counters(self):
        diag = {"jackal_AIC: sensors": {"dropped: imu: non-finite value": "7", "set points clamped": "2",
                                        "stale events": "1", "state": "fresh", "dropped: odd": "?"}}
        self.assertEqual(node_watch.drop_counters(diag), {"dropped: imu: non-finite value": 7,
                                                          "set points clamped": 2, "stale events": 1})
        self.assertEqual(node_watch.drop_counters({}), {})

    def test_figures_formatting(self):
        c = CommandCheck(20.0)
        c.add([3.0, -4.0])
        res = {"seconds": 10.0, "seed": 1, "rate": 1000.0, "sent": {"imu fuzzed": 30, "imu plausible": 70},
               "tags": {"nan": 12}, "phases": {"fuzz": 2}, "check": c, "final_commands": 150,
               "moving_commands": 1, "drops": {"dropped: imu: non-finite value": 12}}
        md = ros_fuzz.markdown(res, [], ["--seconds", "10", "--seed", "1"])
        self.assertIn("`scripts/aic_ros_fuzz.py --seconds 10 --seed 1`", md)
        self.assertIn("| messages sent | 100 (10 /s on average; fuzz stretches at 1000 /s) |", md)
        self.assertIn("| imu | 70 | 30 |", md)
        self.assertIn("| nan | 12 |", md)
        self.assertIn("| commands beyond max_wheel_speed | 0 (limit 20 rad/s; max abs wheel 4.000 rad/s) |", md)
        self.assertIn("| verdict | clean |", md)
        self.assertIn("| dropped: imu: non-finite value | 12 |", md)
        self.assertNotIn("host load", md)
        res["load"] = ("1.00 2.00 3.00", "1.50 2.00 3.00", 2)
        self.assertIn("| host load average (1, 5, 15 min) | before 1.00 2.00 3.00, after 1.50 2.00 3.00; 2 CPU(s) |",
                      ros_fuzz.markdown(res, []))
        lines = ros_fuzz.summary_lines(res, ["the node is not running at the end"])
        self.assertEqual(lines[-1], "  verdict: FINDING: the node is not running at the end")
        self.assertIn("| verdict | FINDING: a / b |", ros_fuzz.markdown(res, ["a | b"]))  # no table break


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("ros_fuzz", GeneratorTest, CheckAndVerdictTest)
