#!/usr/bin/env python3
"""Python unit test: the Python API of the headless closed loop (jackal_aic_tools.compare.run_variant
over jackal_aic_tools.common.closed_loop) and aic_compare.py, on closed_loop_run (seeded sensor
noise, simulated time: deterministic). Checks:

- the API's run of the 0.5 m/s + 0.5 rad/s arc gives exactly closed_loop_run's JSON and trace;
- closed_loop_run's divergence check: the order-4 extension of the thesis's variances (doc/tuning.md,
  'Embedding order and the variance lists') exits 3 with one line naming the cause, and reports it
  and exits 0 with --keep-going; the variance rule's order-4 lists run;
- variant lines (brackets, KEY*=FACTOR, bad lines) and the floored ratios near zero; the shipped
  variant files parse, and each line of the default's ablation changes the default's run;
- aic_compare.py on two variants and one profile: the table, CSV, JSON and figures are written, the
  default's step figures are the scorecard's (aic_scorecard.py's run of the same step), the
  tracking ones closed_loop_run's, the floor the driving set's.
"""
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.realpath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "src"))
SCRIPT = os.path.join(ROOT, "scripts", "aic_compare.py")
PLANT = os.path.join(ROOT, "sim", "config", "plant.yaml")
DEFAULT = os.path.join(ROOT, "config", "default.yaml")
EQUIVALENT = os.path.join(ROOT, "config", "thesis_equivalent.yaml")

from jackal_aic_tools.common import cli, closed_loop  # noqa: E402
from jackal_aic_tools.common.tables import fmt_value  # noqa: E402
from jackal_aic_tools.compare import compare, run_variant, variants  # noqa: E402
from jackal_aic_tools.track import driving  # noqa: E402
from jackal_aic_tools.tune import scorecard  # noqa: E402

#: The order-4 extension of the thesis's variances (each order's var_mu doubled, var_y 1e5).
ORDER4_DIVERGES = ["embedding_order=4", "var_mu=[1.5,2,4,8,16]", "var_y=[2,1e5,1e5,1e5,1e5]"]


def exe():
    return cli.find_executable("closed_loop_run", SCRIPT, "test_compare")


def same(a, b):
    """Arrays equal, NaN where the other is NaN."""
    return a.shape == b.shape and bool(np.all((a == b) | (np.isnan(a) & np.isnan(b))))


class ApiRun(unittest.TestCase):
    def test_the_api_arc_is_closed_loop_runs(self):
        r = run_variant(exe(), DEFAULT, plant_config=PLANT, step=0.5, turn=0.5)
        with tempfile.TemporaryDirectory() as tmp:
            trace = os.path.join(tmp, "arc.csv")
            out = subprocess.run([exe(), "--controller", "aic", "--aic-config", DEFAULT, "--config", PLANT, "--noise",
                                  "--step", "0.5", "--turn", "0.5", "--csv", trace],
                                 stdout=subprocess.PIPE, universal_newlines=True, check=True)
            direct = json.loads(out.stdout)
            columns = driving.tracking.read_columns(trace)
        self.assertEqual(r.result, direct)
        self.assertEqual(sorted(r.trace), sorted(columns))
        for name in columns:
            self.assertTrue(same(r.trace[name], columns[name]), name)
        # The metrics are the JSON's; the belief's RMS is over the trace's profile span.
        self.assertEqual(r.metrics["segments"], direct["segments"])
        self.assertEqual(r.metrics["tracking"]["vx"], direct["tracking"]["truth"]["vx"]["rms"])
        self.assertIsNone(r.metrics["floor"])
        b = r.metrics["belief_rms"]
        self.assertGreater(b["samples"], 100)
        self.assertTrue(0.0 < b["vx"] < 0.1 and 0.0 < b["wz"] < 0.2, b)
        self.assertIsNone(r.diverged)


class FaultMonitorEvents(unittest.TestCase):
    def test_the_json_counts_the_fault_monitors_events(self):
        # closed_loop_run's "fault_monitor": none on the healthy arc; a 0.5 rad/s gyro bias from 3 s
        # for 2 s is isolated once and restored once.
        def events(*fault):
            out = subprocess.run([exe(), "--controller", "aic", "--aic-config", DEFAULT, "--config", PLANT, "--noise",
                                  "--step", "0.5", "--turn", "0.5", "--hold", "8"] + list(fault),
                                 stdout=subprocess.PIPE, universal_newlines=True, check=True)
            return json.loads(out.stdout)["fault_monitor"]
        self.assertEqual(events(), {"isolated": 0, "restored": 0, "detected": 0})
        self.assertEqual(events("--fault", "gyro bias 0.5 3 2"), {"isolated": 1, "restored": 1, "detected": 0})


class Divergence(unittest.TestCase):
    def run_tool(self, sets, keep_going=False):
        cmd = closed_loop.command(exe(), "aic", ["--step", "0.5"], EQUIVALENT, sets, PLANT, noise=False,
                                  keep_going=keep_going)
        return subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)

    def test_the_order_4_extension_fails_loudly(self):
        out = self.run_tool(ORDER4_DIVERGES)
        self.assertEqual(out.returncode, closed_loop.EXIT_DIVERGED, out.stderr)
        lines = [l for l in out.stderr.splitlines() if l.startswith("closed_loop_run")]
        self.assertEqual(len(lines), 1, out.stderr)
        self.assertIn("closed_loop_run: diverged: ", lines[0])
        self.assertIn("runaway", lines[0])
        self.assertIn("runaway", json.loads(out.stdout)["diverged"])
        with self.assertRaises(closed_loop.Diverged) as caught:
            closed_loop.run(exe(), "aic", ["--step", "0.5"], EQUIVALENT, ORDER4_DIVERGES, PLANT)
        self.assertIn("runaway", caught.exception.message)
        # Asked to go on: the same cause in the JSON, exit 0.
        kept = self.run_tool(ORDER4_DIVERGES, keep_going=True)
        self.assertEqual(kept.returncode, 0, kept.stderr)
        self.assertIn("runaway", json.loads(kept.stdout)["diverged"])

    def test_the_documented_order_4_lists_run(self):
        # doc/tuning.md's rule: var_mu doubles per added order, var_y of order 4 at least 8.5e7 (1e9).
        out = self.run_tool(["embedding_order=4", "var_mu=[1.5,2,4,8,16]", "var_y=[2,1e5,1e5,1e5,1e9]"])
        self.assertEqual(out.returncode, 0, out.stderr)
        result = json.loads(out.stdout)
        self.assertIsNone(result["diverged"])
        self.assertTrue(result["segments"][0]["measured"]["settled"])

    def test_a_robot_that_never_moves_has_diverged(self):
        # The open loop with every wheel command clamped to zero: the set point never reaches the wheels.
        cmd = closed_loop.command(exe(), "open", ["--step", "0.5"], plant_config=PLANT, noise=False,
                                  plant_sets=["motor.max_torque=0.0001"])
        out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        self.assertEqual(out.returncode, closed_loop.EXIT_DIVERGED, out.stderr)
        self.assertIn("never moved", out.stderr)


class VariantLines(unittest.TestCase):
    def test_lines(self):
        v = variants.parse("o4=default:embedding_order=4,var_mu=[1,2,3,4,5],k_a*=0.5", ROOT,
                           lambda path: {"k_a": 3.0, "embedding_order": 2})
        self.assertEqual(v.name, "o4")
        self.assertEqual(v.config, DEFAULT)
        self.assertEqual(v.sets, ["embedding_order=4", "var_mu=[1,2,3,4,5]", "k_a=1.5"])
        self.assertEqual(variants.parse("plain=config/default.yaml", ROOT).sets, [])
        for bad in ("no_base", "x=no_such_config", "x=default:k_a", "x=default:tau*=2", "bad name=default"):
            with self.assertRaises(variants.VariantError):
                variants.parse(bad, ROOT, (lambda path: {"tau": "a"}) if "*" in bad else None)
        with self.assertRaises(variants.VariantError):
            variants.check_names([variants.parse("stock=default", ROOT)])

    def test_an_overlay_stacks_its_keys_after_the_base(self):
        # config/goal_model.yaml over config/default.yaml, as the node loads them: its keys in the
        # file's order, then the overrides; KEY*= scales the overlay's value where it sets one, the
        # effective file's otherwise.
        effective = lambda path: {"k_a": 3.0, "tau": 0.01}
        v = variants.parse("gm=default+goal_model:k_a*=0.001,tau*=2", ROOT, effective)
        self.assertEqual(v.config, DEFAULT)
        with open(os.path.join(ROOT, "config", "goal_model.yaml")) as f:
            keys = [line.split(":")[0] for line in f if line[:1].isalpha()]
        self.assertEqual(keys, ["belief_model", "max_goal_rate_angular"])
        self.assertEqual([s.split("=")[0] for s in v.sets], keys + ["k_a", "tau"])
        self.assertEqual(v.sets[0], "belief_model=goal")
        self.assertEqual(v.sets[-2:], ["k_a=0.003", "tau=0.02"])
        for bad in ("x=default+no_such_overlay", "x=default+"):
            with self.assertRaises(variants.VariantError):
                variants.parse(bad, ROOT)
        with tempfile.TemporaryDirectory() as tmp:  # an overlay that is not a mapping of keys
            path = os.path.join(tmp, "list.yaml")
            with open(path, "w") as f:
                f.write("- belief_model\n- robot\n")
            with self.assertRaises(variants.VariantError):
                variants.parse("x=default+" + path, ROOT)

    def test_floored_ratios(self):
        self.assertEqual(compare.floored_ratio(0.0, 0.0, "m/s"), 1.0)
        self.assertEqual(compare.floored_ratio(0.0001, 0.004, "m/s"), 0.5)
        self.assertAlmostEqual(compare.floored_ratio(0.1, 0.2, "s"), 0.5)
        self.assertIsNone(compare.floored_ratio(None, 0.2, "s"))
        self.assertIsNone(compare.floored_ratio(float("nan"), 0.2, "s"))


class CompareTool(unittest.TestCase):
    def test_two_variants_on_one_profile(self):
        with tempfile.TemporaryDirectory() as tmp:
            profile = os.path.join(tmp, "short.csv")
            with open(profile, "w") as f:
                f.write("t,vx,wz\n0,0.4,0\n1.5,0.4,0.5\n3,0,0\n4,0,0\n")
            out = subprocess.run([sys.executable, SCRIPT, "--variant", "default=default", "--variant",
                                  "slow=default:k_a*=0.5", "--profiles", profile, "--out", tmp],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("tracking RMS / floor", out.stdout)
            for name in ("compare.csv", "compare.json", "tracking_ratios.png", "tracking_ratios.pdf", "steps.png",
                         "steps.pdf", "belief_error.png", "belief_error.pdf"):
                self.assertTrue(os.path.isfile(os.path.join(tmp, name)), name)
            with open(os.path.join(tmp, "compare.csv")) as f:
                cells = {(r["metric"], r["column"]): r for r in csv.DictReader(f)}
            # The default's 0.5 m/s step is the scorecard's run (criterion 1, seed 42).
            ref = scorecard.closed_loop(exe(), "aic", scorecard.step_profile(0.5), DEFAULT, PLANT, ["sensors.seed=42"])
            for metric in ("rise", "settling", "overshoot"):
                self.assertEqual(float(cells[("0.5 m/s %s" % metric, "default")]["value"]),
                                 ref["segments"][0]["measured"][metric])
            # Tracking: closed_loop_run's RMS; the floor the driving set's at the plant's latency.
            k_a = cli.effective_config([DEFAULT], SCRIPT, "test_compare")["k_a"] * 0.5
            track = closed_loop.run(exe(), "aic", ["--profile", profile], DEFAULT, ["k_a=%s" % fmt_value(k_a)], PLANT)
            self.assertAlmostEqual(float(cells[("short vx RMS", "slow")]["value"]),
                                   track.result["tracking"]["truth"]["vx"]["rms"], places=12)
            floor = driving.floor_rms(profile, track.result["command_delay"])
            self.assertEqual(float(cells[("short wz RMS", "floor")]["value"]), floor["wz"])
            ratio = float(cells[("short vx RMS", "slow")]["ratio"])
            stock = float(cells[("short vx RMS", "stock")]["value"])
            self.assertTrue(math.isclose(ratio, max(track.result["tracking"]["truth"]["vx"]["rms"], 0.002) /
                                         max(stock, 0.002)))


class MarkdownPage(unittest.TestCase):
    """compare.markdown_page names the plants the runs were on and counts their channels."""

    def test_the_page_names_its_plants(self):
        class V:
            name, config, sets = "d", DEFAULT, ["k=1"]
        rows = []
        for label in ("p vx RMS", "p wz RMS", "p (td) vx RMS", "p (td) wz RMS"):
            unit = "m/s" if " vx " in label else "rad/s"
            rows.append({"section": "tracking", "label": label, "unit": unit, "ref": "stock",
                         "values": {"d": 0.1, "stock": 0.2, "floor": 0.05}, "ratios": {"d": 0.5, "floor": 0.25},
                         "diverged": {}})
        summ = compare.summary(rows, [V])
        one = compare.markdown_page(rows, summ, [V], "cmd", ROOT, "T")
        self.assertIn("on the default plant, noisy sensors", one)
        two = compare.markdown_page(rows, summ, [V], "cmd", ROOT, "T", plants=["default", "/x/td.yaml"])
        self.assertIn("on each of 2 plants (the default plant, `td`)", two)
        self.assertIn("over the 4 tracking channels", two)
        self.assertIn("| d | `config/default.yaml` `k=1` | 0.500 | 2.000 |", two)


class ShippedVariantFiles(unittest.TestCase):
    """The variant files of config/compare parse, and every line of the default's ablation acts on
    the default: a switch the robot model does not read (the goal model's action_prior_gain, k_a,
    reference_time_constant) would leave its run bit-identical to the default's."""

    def effective(self, path):
        return cli.effective_config([path], SCRIPT, "test_compare")

    def test_every_variant_file_parses(self):
        files = sorted(f for f in os.listdir(os.path.join(ROOT, "config", "compare")) if f.endswith(".txt"))
        self.assertIn("default_ablation.txt", files)
        for name in files:
            found = variants.read_file(os.path.join(ROOT, "config", "compare", name), ROOT, self.effective)
            self.assertGreater(len(found), 1, name)
            variants.check_names(found)

    def test_each_part_of_the_default_ablation_acts(self):
        found = variants.read_file(os.path.join(ROOT, "config", "compare", "default_ablation.txt"), ROOT,
                                   self.effective)
        self.assertEqual(found[0].name, "default")
        deficit = os.path.join(ROOT, "sim", "config", "variants", "turn_deficit.yaml")
        profile = os.path.join(ROOT, "sim", "profiles", "s_curves.csv")

        def rms(v):
            r = closed_loop.run(exe(), "aic", ["--profile", profile], v.config, v.sets, PLANT, [deficit],
                                keep_going=True)
            return [r.result["tracking"]["truth"][ch]["rms"] for ch in ("vx", "wz")]

        base = rms(found[0])
        for v in found[1:]:
            if v.config == DEFAULT:
                self.assertNotEqual(rms(v), base, "%s leaves the default's run unchanged" % v.name)


class KeysWithoutEffect(unittest.TestCase):
    """The parameter table's "belief models" column (ParamSpec::models; the node and the tools warn
    of a key set for another model): every key it gives to other models leaves closed-loop runs of
    this model bit-identical, commands, beliefs and the robot's motion, and a key the model reads
    does change them. Two runs, noisy sensors: a step into an arc with a gyro offset appearing
    mid-arc; a set point dropped from 1.1 m/s to zero with the rated payload forward, which lifts
    the rear wheels and trips the tip guard (its hold of the path is a branch of its own)."""

    COLUMNS = ("command", "command_yaw", "belief", "belief_yaw", "v_true", "yaw_true", "separation",
               "gyro_offset", "fdi_statistic")
    SCENARIOS = (["--step", "0.5", "--turn", "0.5", "--hold", "2.5", "--fault", "gyro bias 0.1 2 1"],
                 ["--square", "0", "1.1", "--rest", "0.5", "--period", "3", "--cycles", "1", "--overlay",
                  os.path.join(ROOT, "sim", "config", "variants", "payload_20kg_forward.yaml")])
    MODELS = {"robot": [], "goal": ["goal_model.yaml"], "unbiased": ["unbiased.yaml"]}
    READ = {"robot": "action_gain", "goal": "tau", "unbiased": "tau"}

    @classmethod
    def setUpClass(cls):
        table = subprocess.run([cli.find_executable("aic_params", SCRIPT, "test_compare"), "--markdown"],
                               capture_output=True, text=True, check=True).stdout
        cls.models = {}
        for line in table.splitlines():
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
            if len(cells) == 8 and cells[0].startswith("`"):
                cls.models[cells[0].split("`")[1]] = cells[6]

    def run_loop(self, config, sets, results=None):
        """The COLUMNS of each scenario's trace (a list per scenario), or None if a run fails; each
        run's JSON appended to `results` when it is a list."""
        runs = []
        for scenario in self.SCENARIOS:
            with tempfile.TemporaryDirectory() as tmp:
                trace = os.path.join(tmp, "trace.csv")
                cmd = [exe(), "--controller", "aic", "--aic-config", config, "--noise", "--csv", trace] + scenario
                for s in sets:
                    cmd += ["--aic-set", s]
                out = subprocess.run(cmd, capture_output=True, text=True)
                if out.returncode != 0:
                    return None
                with open(trace) as f:
                    rows = list(csv.reader(f))
                keep = [rows[0].index(c) for c in self.COLUMNS]
                runs.append([[r[i] for i in keep] for r in rows[1:]])
                if results is not None:
                    results.append(json.loads(out.stdout))
        return runs

    @staticmethod
    def changed(value):
        """Values to set instead of `value` (from aic_params --yaml), the first valid one is used."""
        if isinstance(value, bool):
            return [str(not value).lower()]
        if isinstance(value, list):
            return ["[%s]" % ",".join(repr(2.0 * x) for x in value)]
        if isinstance(value, str):
            return [{"euler": "exact", "exact": "euler"}[value]]
        return [repr(x) for x in ((0.5 * value, 1.5 * value) if value else (0.05, 0.5))]

    def test_the_column_is_complete(self):
        self.assertGreater(len(self.models), 90)
        self.assertEqual(self.models["tau"], "goal and unbiased")
        self.assertEqual(self.models["latency"], "robot")
        self.assertEqual(self.models["goal_response_time_constant"], "unbiased")
        self.assertEqual(self.models["max_wheel_speed"], "all")

    def test_a_key_of_another_model_leaves_the_run_unchanged(self):
        for model, overlays in sorted(self.MODELS.items()):
            with tempfile.TemporaryDirectory() as tmp:
                config = os.path.join(tmp, "config.yaml")
                cmd = [cli.find_executable("aic_params", SCRIPT, "test_compare"), "--yaml", "--config", DEFAULT]
                for o in overlays:
                    cmd += ["--config", os.path.join(ROOT, "config", o)]
                with open(config, "w") as f:
                    f.write(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
                import yaml
                with open(config) as f:
                    values = yaml.safe_load(f)
                results = []
                base = self.run_loop(config, [], results)
                self.assertIsNotNone(base, model)
                self.assertGreaterEqual(results[1]["tip_guard"]["trips"], 1,
                                        "%s: the payload's drop trips no tip guard" % model)
                self.assertNotEqual(self.run_loop(config, ["%s=%s" % (self.READ[model], self.changed(
                    values[self.READ[model]])[0])]), base, "%s: a key it reads changes nothing" % model)
                others = sorted(k for k, m in self.models.items() if m != "all" and model not in m.split(" "))
                self.assertGreater(len(others), 10, model)
                for key in others:
                    runs = [self.run_loop(config, ["%s=%s" % (key, v)]) for v in self.changed(values[key])]
                    runs = [r for r in runs if r is not None]
                    self.assertTrue(runs, "%s: no valid value of %s to try" % (model, key))
                    self.assertEqual(runs[0], base, "%s: %s changes the run" % (model, key))


if __name__ == "__main__":
    import pyunit  # test/pyunit.py, beside this file
    pyunit.main("compare", ApiRun, FaultMonitorEvents, Divergence, VariantLines, CompareTool, MarkdownPage, ShippedVariantFiles,
                KeysWithoutEffect)
