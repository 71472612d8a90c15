#!/usr/bin/env python3
"""Python unit test: aic_tune.py's search spaces and costs (jackal_aic_tools.tune.tune_space,
tune_cost, tune.fit_fopdt) on made-up predictions and step figures whose cost is worked out by
hand; no simulator, no tool runs. Deterministic."""
import math
import os
import tempfile
import types
import unittest

import numpy as np

from jackal_aic_tools.tune import tune, tune_cost, tune_pi, tune_space


def args(**kw):
    """The tuner's bounds as aic_tune.py parses them by default, changed by ``kw``."""
    a = dict(seeds=[42, 1], overshoot=4.0, robust_overshoot=10.0, turn_weight=1.0, turn_ratio=0.97,
             max_radius=0.98, robust=0.2)
    a.update(kw)
    return types.SimpleNamespace(**a)


def m(settling=None, rise=0.2, overshoot=0.0, sse=0.0, settled=True, runaways=0):
    """Step figures as closed_loop_run (tune.StepRunner) gives them."""
    return {"runaways": runaways, "max": 1.0, "rise": rise, "settling": settling, "overshoot": overshoot,
            "sse": sse, "settled": settled}


class FakeSteps(object):
    """A step runner answering from a table: (controller, v, channel, plant_sets) -> figures."""

    def __init__(self, table):
        self.table = table
        self.calls = []

    def __call__(self, overrides, v, noise=False, channel="linear", controller="aic", plant_sets=(), hold=3.0):
        self.calls.append((controller, v, channel, tuple(plant_sets), noise, hold))
        return dict(self.table[(controller, v, channel, tuple(plant_sets))])


# The stock controller's reference: settling 1 s and rise 0.5 s on every step of the first seed,
# 2 s on seed 1's 0.5 m/s step, the turn 2 s.
REF = {("step", v, 42): m(settling=1.0, rise=0.5) for v in tune_cost.COST_STEPS}
REF[("step", 0.5, 1)] = m(settling=2.0, rise=0.5)
REF[("turn", 1.0)] = m(settling=2.0, rise=0.5)

S42, S1 = ("sensors.seed=42",), ("sensors.seed=1",)
DELAY_LOW, DELAY_HIGH = (tune_cost.ROBUST_DELAYS[0],), (tune_cost.ROBUST_DELAYS[1],)


def aic_table(changes=None):
    """The AIC's figures of every run of sim_cost (see SimCostTest for the cost of each term)."""
    t = {
        ("aic", 0.1, "linear", S42): m(settling=0.5, overshoot=5.0, sse=0.002),  # 1 % over, 2 % sse
        ("aic", 0.3, "linear", S42): m(settling=0.6),
        ("aic", 0.5, "linear", S42): m(settling=0.8, rise=0.25),
        ("aic", 1.0, "linear", S42): m(settling=None, settled=False, sse=0.05),  # 3.05 s, 5 % sse
        ("aic", 0.5, "linear", S1): m(settling=1.2),
        ("aic", 0.5, "linear", DELAY_LOW): m(settling=0.9, overshoot=12.0),
        ("aic", 0.5, "linear", DELAY_HIGH): m(settling=None, settled=False),
        ("aic", 1.0, "angular", ()): m(settling=2.2, overshoot=15.0),
    }
    t.update(changes or {})
    return t


# Term by term (tune_cost.sim_cost's docstring):
#   worst 0.5 m/s settling ratio: max(0.8 / 1.0, 1.2 / 2.0)                 = 0.8
#   0.5 x rise ratio 0.25 / 0.5                                             = 0.25
#   0.25 x mean settling ratio of 0.3 and 1.0 m/s: (0.6 + 3.05) / 2         = 0.45625
#   overshoot above 4 %: 0.2 x (5 - 4) on the 0.1 m/s step                 = 0.2
#   sse above 1 %: 0.2 x (2 - 1) at 0.1 m/s, 0.2 x (5 - 1) at 1.0 m/s       = 1.0
#   robustness: 0.05 x (12 - 10) overshoot, 2 for the unsettled run         = 2.1
#   turn: 1.0 x (2.2 / 2.0 - 0.97) + 0.02 x (15 - 10)                       = 0.23
EXPECTED = 0.8 + 0.25 + 0.45625 + 0.2 + 1.0 + 2.1 + 0.23


class SimCostTest(unittest.TestCase):

    def cost(self, changes=None, a=None):
        return tune_cost.sim_cost(["k_a=5"], a or args(), REF, FakeSteps(aic_table(changes)))

    def test_every_term(self):
        self.assertAlmostEqual(self.cost(), EXPECTED, places=9)

    def test_each_term_moves_the_cost(self):
        # Remove one term at a time: the cost drops by exactly that term.
        self.assertAlmostEqual(self.cost({("aic", 0.5, "linear", S42): m(settling=0.5, rise=0.25)}),
                               EXPECTED - 0.8 + 0.6, places=9)  # worst ratio now seed 1's 0.6
        self.assertAlmostEqual(self.cost({("aic", 0.5, "linear", S42): m(settling=0.8, rise=0.5)}),
                               EXPECTED + 0.25, places=9)
        self.assertAlmostEqual(self.cost({("aic", 0.5, "linear", S42): m(settling=0.8, rise=None)}),
                               EXPECTED - 0.25 + 1.5, places=9)  # never rose: 3 x 0.5
        self.assertAlmostEqual(self.cost({("aic", 1.0, "linear", S42): m(settling=0.4, sse=0.05)}),
                               EXPECTED - 0.25 * (3.05 - 0.4) / 2.0, places=9)
        self.assertAlmostEqual(self.cost({("aic", 0.5, "linear", DELAY_HIGH): m(settling=0.9)}),
                               EXPECTED - 2.0, places=9)
        self.assertAlmostEqual(self.cost(a=args(turn_weight=0.0)), EXPECTED - 0.23, places=9)
        self.assertAlmostEqual(self.cost(a=args(turn_weight=2.0)), EXPECTED + 0.13, places=9)
        self.assertAlmostEqual(self.cost(a=args(overshoot=6.0)), EXPECTED - 0.2, places=9)
        self.assertAlmostEqual(self.cost(a=args(robust_overshoot=20.0)), EXPECTED - 0.1, places=9)

    def test_a_runaway_scores_10(self):
        self.assertEqual(self.cost({("aic", 0.3, "linear", S42): m(settling=0.6, runaways=1)}), 10.0)
        self.assertEqual(self.cost({("aic", 0.5, "linear", DELAY_LOW): m(settling=0.6, runaways=2)}), 10.0)
        self.assertEqual(self.cost({("aic", 1.0, "angular", ()): m(settling=2.0, runaways=1)}), 10.0)

    def test_the_runs_asked_for(self):
        steps = FakeSteps(aic_table())
        tune_cost.sim_cost(["k_a=5"], args(), REF, steps)
        noisy = [c for c in steps.calls if c[4]]
        self.assertEqual(sorted((c[1], c[2], c[3]) for c in noisy),
                         sorted([(v, "linear", S42) for v in tune_cost.COST_STEPS] + [(0.5, "linear", S1),
                                                                                     (1.0, "angular", ())]))
        self.assertEqual(sorted(c[3] for c in steps.calls if not c[4]), [DELAY_LOW, DELAY_HIGH])
        self.assertEqual([c[5] for c in steps.calls if c[2] == "angular"], [8.0])

    def test_settle_or_penalty(self):
        self.assertEqual(tune_cost.settle_or_penalty(m(settling=0.7), 0.5), 0.7)
        self.assertAlmostEqual(tune_cost.settle_or_penalty(m(settling=None, settled=False, sse=-0.1), 0.5), 3.2)
        self.assertAlmostEqual(tune_cost.settle_or_penalty(m(settling=None, settled=False, sse=None), 0.5), 4.0)

    def test_stock_reference(self):
        table = {("stock", v, "linear", S42): m(settling=v) for v in tune_cost.COST_STEPS}
        table[("stock", 0.5, "linear", S1)] = m(settling=9.0)
        table[("stock", 1.0, "angular", ())] = m(settling=7.0)
        ref = tune_cost.stock_reference(args(), FakeSteps(table))
        self.assertEqual(sorted(ref, key=str), sorted([("step", v, 42) for v in tune_cost.COST_STEPS] +
                                                      [("step", 0.5, 1), ("turn", 1.0)], key=str))
        self.assertEqual(ref[("step", 0.3, 42)]["settling"], 0.3)
        self.assertEqual(ref[("step", 0.5, 1)]["settling"], 9.0)
        self.assertEqual(ref[("turn", 1.0)]["settling"], 7.0)


class ModelCostTest(unittest.TestCase):
    PLANT = {"gain": 1.0, "time_constant": 0.1, "delay": 0.1}

    def predictor(self, nominal, corner):
        calls = []

        def predict(overrides, plant):
            calls.append(plant)
            return dict(nominal if plant == self.PLANT else corner)
        return predict, calls

    def cost(self, nominal, corner, **kw):
        predict, calls = self.predictor(nominal, corner)
        x = [math.log10(v) for v in (0.01, 0.1, 10.0, 1.0, 100.0)]
        corners = tune_cost.plant_corners(self.PLANT, 0.2)
        return tune_cost.model_cost(x, 2, predict, corners, args(**kw)), calls

    def test_worst_corner_and_penalties(self):
        good = {"ok": True, "stable": True, "rise": 0.2, "settling": 0.5, "overshoot": 3.0, "spectral_radius": 0.9}
        corner = dict(good, settling=0.6, overshoot=6.0, spectral_radius=0.99)
        c, calls = self.cost(good, corner)
        # worst settling 0.6 + 0.05 x (6 - 4) + 20 x (0.99 - 0.98)
        self.assertAlmostEqual(c, 0.6 + 0.1 + 0.2, places=9)
        self.assertEqual(len(calls), 5)
        c, _ = self.cost(good, dict(corner, settling=None))
        self.assertAlmostEqual(c, 5.0 + 0.1 + 0.2, places=9)  # unsettled counts as 5 s
        c, _ = self.cost(good, good)
        self.assertAlmostEqual(c, 0.5, places=9)

    def test_invalid_candidates(self):
        good = {"ok": True, "stable": True, "rise": 0.2, "settling": 0.5, "overshoot": 0.0, "spectral_radius": 0.9}
        self.assertEqual(self.cost(dict(good, stable=False), good)[0], 100.0)
        self.assertEqual(self.cost(dict(good, ok=False), good)[0], 100.0)
        self.assertEqual(self.cost(dict(good, rise=None), good)[0], 50.0)
        self.assertEqual(self.cost(good, dict(good, stable=False))[0], 20.0)

    def test_plant_corners(self):
        corners = tune_cost.plant_corners(self.PLANT, 0.2)
        self.assertEqual(corners[0], self.PLANT)
        self.assertEqual(sorted((round(c["gain"], 9), round(c["delay"], 9)) for c in corners[1:]),
                         [(0.8, 0.08), (0.8, 0.12), (1.2, 0.08), (1.2, 0.12)])
        self.assertTrue(all(c["time_constant"] == 0.1 for c in corners))


class SpaceTest(unittest.TestCase):

    def test_candidate(self):
        x = [math.log10(v) for v in (0.01, 0.1, 10.0, 1.5, 100.0, 3.0, 1.0)]
        o = tune_space.candidate_overrides(x, 3)
        self.assertAlmostEqual(o["tau"], 0.01)
        self.assertAlmostEqual(o["k_a"], 10.0)
        np.testing.assert_allclose(o["var_mu"], [1.5, 2.0, 4.0, 8.0])  # table C-1's shape
        np.testing.assert_allclose(o["var_y"], [2.0, 100.0, 1e5, 1e5])
        self.assertAlmostEqual(o["max_action_lead"], 3.0)
        self.assertEqual(o["embedding_order"], 3)
        self.assertEqual(o["generalized_goal"], "false")
        self.assertNotIn("max_action_lead", tune_space.candidate_overrides(x[:5], 2))
        args_ = tune_space.to_args({"tau": 0.01, "var_y": [2.0, 1000.0], "integrator": "exact"})
        self.assertEqual(args_, ["integrator=exact", "tau=0.01", "var_y=[2.0,1000.0]"])

    def test_base_vector_round_trip(self):
        d = {"embedding_order": 2, "tau": 0.02, "k_mu": 0.3, "k_a": 12.0, "var_mu": [1.5, 2.0, 4.0],
             "var_y": [2.0, 50.0, 1e5], "max_action_lead": 2.0}
        order, x = tune_space.base_vector(d)
        self.assertEqual(order, 2)
        o = tune_space.candidate_overrides(x, order)
        for k in ("tau", "k_mu", "k_a", "max_action_lead"):
            self.assertAlmostEqual(o[k], d[k] if k in d else None)
        self.assertAlmostEqual(o["max_action_lead_turn"], 1.0)  # absent: 1 rad/s
        self.assertIsNone(tune_space.base_vector(dict(d, tau=0.0)))
        self.assertIsNone(tune_space.base_vector({"tau": 0.1}))

    def test_driving_unit_round_trip(self):
        base = {"var_y": [2.0, 40.0, 1e5], "k_a": 8.0, "tau": 0.01, "action_prior_gain": 0.3,
                "reference_delay": 0.05}
        u = tune_space.driving_unit(base)
        v = tune_space.driving_values(u, base["var_y"])
        self.assertAlmostEqual(v["k_a"], 8.0)
        self.assertAlmostEqual(v["var_y"][1], 40.0)
        self.assertEqual(v["var_y"][0], 2.0)
        self.assertAlmostEqual(v["action_prior_gain"], 0.3)
        self.assertAlmostEqual(v["reference_delay"], 0.05)
        lo, hi, _ = tune_space.DRIVING_SPACE["goal_lead"]
        self.assertAlmostEqual(v["goal_lead"], (lo + hi) / 2.0)  # absent: the middle
        self.assertEqual(v["generalized_goal"], "true")
        over = tune_space.driving_values(np.full(len(u), 1.5), base["var_y"])
        self.assertAlmostEqual(over["k_a"], tune_space.DRIVING_SPACE["k_a"][1])  # clipped to the box

    def test_an_unbiased_base_searches_its_own_space(self):
        base = {"var_y": [2.0, 40.0, 1e5], "belief_model": "unbiased", "k_mu": 20.0, "tau": 0.1,
                "goal_response_time_constant": 0.05}
        space = tune_space.driving_space(base)
        self.assertIs(space, tune_space.UNBIASED_DRIVING_SPACE)
        self.assertIs(tune_space.driving_space({"belief_model": "goal"}), tune_space.DRIVING_SPACE)
        v = tune_space.driving_values(tune_space.driving_unit(base, space), base["var_y"], space)
        self.assertAlmostEqual(v["k_mu"], 20.0)  # above DRIVING_SPACE's k_mu range
        self.assertAlmostEqual(v["goal_response_time_constant"], 0.05)
        self.assertNotIn("goal_response_time_constant",
                         tune_space.driving_values(tune_space.driving_unit(base), base["var_y"]))

    def test_a_key_that_is_off_at_zero_enters_the_driving_space_linearly(self):
        # doc/extending.md, 'The tuner's space': the slew limit's line of DRIVING_SPACE, on a linear
        # scale so that 0 (off) stays reachable; never in SPACE (the linear model leaves it out).
        space = dict(tune_space.DRIVING_SPACE, action_slew_limit=(0.0, 60.0, False))
        base = {"var_y": [2.0, 40.0, 1e5], "action_slew_limit": 0.0}
        v = tune_space.driving_values(tune_space.driving_unit(base, space), base["var_y"], space)
        self.assertEqual(v["action_slew_limit"], 0.0)
        v = tune_space.driving_values(tune_space.driving_unit(dict(base, action_slew_limit=20.0), space),
                                      base["var_y"], space)
        self.assertAlmostEqual(v["action_slew_limit"], 20.0)
        self.assertIn("action_slew_limit=20", tune_space.to_args(v))
        self.assertNotIn("action_slew_limit", tune_space.SPACE)

    def test_yaml_numbers(self):
        self.assertEqual(tune_space.yaml_float(1000.0), "1000.0")
        self.assertEqual(tune_space.yaml_float(0.0123456), "0.01235")
        self.assertEqual(tune_space.yaml_float(1e5), "100000.0")
        self.assertEqual(tune_space.yaml_float(2e-5), "0.0")  # below %.1f: what the file keeps
        self.assertEqual(tune_space.yaml_list([2.0, 1e5]), "[2.0, 100000.0]")

    def test_write_yaml(self):
        with tempfile.TemporaryDirectory() as tmp:
            base = os.path.join(tmp, "base.yaml")
            with open(base, "w") as f:
                f.write("# header\n# tuned by aic_tune.py: old\ntau: 0.05  # s\nnested:\n  tau: 1\nk_a: 3\n")
            out = os.path.join(tmp, "out.yaml")
            tune_space.write_yaml(out, base, {"tau": 0.002, "k_a": 12, "var_y": [2.0, 30.0]}, "# tuned by aic_tune.py: new")
            with open(out) as f:
                self.assertEqual(f.read(), "# header\n# tuned by aic_tune.py: new\ntau: 0.002  # s\nnested:\n"
                                           "  tau: 1\nk_a: 12\nvar_y: [2.0, 30.0]\n")


class PiGainsTest(unittest.TestCase):
    """tune_pi: the unit box of the peer's gains and the YAML writer."""

    def test_unit_box_round_trip_and_sets(self):
        gains = {"wheel.kp": 0.1, "wheel.ki": 1.0, "yaw.kp": 0.05, "yaw.ki": 2.0}
        back = tune_pi.from_unit(tune_pi.to_unit(gains))
        for k, v in gains.items():
            self.assertAlmostEqual(back[k], v)
        self.assertEqual(tune_pi.to_sets({"wheel.kp": 0.1}), ["wheel.kp=0.1"])
        self.assertEqual(tune_pi.to_unit({})[0], 0.5)  # absent: the middle

    def test_write_gains_in_place_and_idempotent(self):
        base = "# header\n\n# inner loops\nwheel:\n  kp: 0.3  # [-]\n  ki: 3.0\n# outer\nyaw:\n  kp: 0.3\n  ki: 3.0\n"
        gains = {"wheel.kp": 0.07, "wheel.ki": 0.1, "yaw.kp": 0.06, "yaw.ki": 1.2}
        stamp = tune_pi.STAMP + " (cost 1):\n#   aic_tune.py --driving --controller pi"
        with tempfile.TemporaryDirectory() as tmp:
            src, one, two = (os.path.join(tmp, n) for n in ("base.yaml", "one.yaml", "two.yaml"))
            with open(src, "w") as f:
                f.write(base)
            tune_pi.write_gains(one, src, gains, stamp)
            tune_pi.write_gains(two, one, gains, stamp)
            with open(one) as f:
                text = f.read()
            with open(two) as f:
                self.assertEqual(f.read(), text)
            self.assertEqual(tune_pi.base_gains(one), gains)
            lines = text.splitlines()
            self.assertEqual(lines[2], tune_pi.STAMP + " (cost 1):")  # above the group's comment
            self.assertEqual(lines[4], "# inner loops")
            with self.assertRaises(KeyError):
                tune_pi.write_gains(two, src, {"yaw.kd": 1.0}, stamp)


class FopdtTest(unittest.TestCase):

    def test_recovers_a_known_loop(self):
        t = np.arange(0.0, 3.0, 0.01)
        u = np.where(t < 0.5, 0.2, np.where(t < 1.8, 0.6, 0.3))
        k, tp, d = 0.9, 0.08, 0.05
        y = np.empty_like(t)
        for i, ti in enumerate(t):  # the analytic response of K exp(-d s) / (T_p s + 1) to the steps
            level = 0.2 * k
            for t_step, du in ((0.5, 0.4), (1.8, -0.3)):
                if ti > t_step + d:
                    level += k * du * (1.0 - math.exp(-(ti - t_step - d) / tp))
            y[i] = level
        gain, time_constant, delay, residuals = tune.fit_fopdt(t, u, y)
        self.assertAlmostEqual(gain, k, delta=0.01)
        self.assertAlmostEqual(time_constant, tp, delta=0.005)
        self.assertAlmostEqual(delay, d, delta=0.003)
        self.assertLess(float(np.sqrt(np.mean(residuals ** 2))), 0.005)


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("tune", SimCostTest, ModelCostTest, SpaceTest, PiGainsTest, FopdtTest)
