#!/usr/bin/env python3
"""Structural ablations: the same runs with one rule of the control law taken out of the code.

A stage the configuration switches off (the feed-forward, the reference model, the learners) is
ablated with aic_compare.py alone (config/compare/default_ablation.txt). A rule inside a stage has
no parameter to switch it off: the shortfall's jumps, the drop of a jump at a turn's change, a
part of the slip ratio's learning gate, the reference path's wheel-frame bound. This tool ablates
those by an edit of their source, as dev/mutants.py seeds a fault, and measures the edit with the
comparison's runs instead of the tests:

  1. it copies the repository into a scratch catkin workspace (dev/mutants.py's Workspace) and
     builds closed_loop_run and aic_params there;
  2. per distinct variant of the list, it runs that copy's aic_compare.py on the tree as it is
     ("with" the rule), all before the first edit is built;
  3. per ablation, it applies the edit, rebuilds, runs the same comparison ("without" the rule),
     restores the file and rebuilds.

Both sides are the same runs (the scorecard's steps and the six profiles of sim/profiles on each
plant, noisy sensors, fixed seeds, the stock controller beside them), so a difference is the rule's.

    dev/ablations.py [--list dev/ablations.txt] [--work DIR] [--only ID ...] [--markdown FILE]
                     [--jobs N] [--threshold F]

--work: the scratch workspace (default .ws/ablations, git-ignored; kept between runs).
--markdown: write the results page there (doc/results/ablations.md). --threshold: list a
profile's channel under its plant when its RMS moves by more than this fraction (default 0.05).
Exit 0 when every run finished, 1 when an edit did not build or a comparison failed, 2 on a usage
or setup error.

List format: dev/mutants.py's (blocks of 'KEY: value' lines, '|' continues a value), with keys:
  id, what, file, find, replace   as for a mutant: the edit that takes the rule out
  variant  the configuration it is measured on, an aic_compare.py variant line without its name,
           BASE[+OVERLAY][:KEY=VALUE,...] (jackal_aic_tools.compare.variants; default: default)
  plants   space-separated plants: 'default' or overlay YAML paths in the repository (default:
           default and the four variants of the tracking page, PLANTS)

Per plant the page gives the geometric means over its 12 channels (aic_compare.py's floored
ratios, doc/tools.md, 'Comparing variants'): tracking RMS / floor and / stock, with -> without;
floor / stock (the floor is computed by the same build, so a rule it shares moves it); the steps'
rise and settling / stock and the belief - truth RMS over the profiles; and the channels whose RMS
moved by more than --threshold.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(REPO, "src"))
import mutants  # noqa: E402 (dev/mutants.py: the list format, the edit, the scratch workspace)
from jackal_aic_tools.common.tables import fmt  # noqa: E402
from jackal_aic_tools.compare.compare import floored_ratio  # noqa: E402
from jackal_aic_tools.track import plant_limits  # noqa: E402

KEYS = ("id", "what", "file", "find", "replace", "variant", "plants")
#: The default plants: the nominal plant and the four variants of doc/results/tracking.md.
PLANTS = ["default"] + ["sim/config/variants/%s.yaml" % v for v in
                        ("turn_deficit", "latency_minus_20", "latency_plus_20", "payload_20kg")]
#: The programs aic_compare.py runs.
TARGETS = ["closed_loop_run", "aic_params"]


def ablation_defaults(block):
    """An ablation's 'variant' (default 'default') and 'plants' (a list, default PLANTS)."""
    block["variant"] = block.get("variant", "default").strip()
    block["plants"] = block["plants"].split() if "plants" in block else list(PLANTS)


def parse_list(text, name="ablations list"):
    """The ablations of a list file's text: dicts with KEYS (mutants.parse_list with this module's
    keys). Raises mutants.ListError naming the line on a malformed entry."""
    return mutants.parse_list(text, name, keys=KEYS, finish=ablation_defaults)


def plant_tag(plant):
    """The suffix aic_compare.py gives a plant's rows: '' for the default plant, ' (<stem>)' else."""
    return "" if plant == "default" else " (%s)" % os.path.splitext(os.path.basename(plant))[0]


def per_plant(result, plants):
    """Per plant, the figures of one compare.json ``result`` (its only variant): a dict plant ->
    {"floor", "stock", "floor_stock": geometric means over the plant's tracking channels of the
    floored ratios RMS / floor, RMS / stock and floor / stock; "belief_vx", "belief_wz": the mean
    belief - truth RMS over its profiles [m/s, rad/s]; "worst_belief": (the largest RMS(belief -
    truth) / RMS(set point - truth) of its channels, that channel's label), the honest-belief measure
    of doc/active_inference.md ('The robot model', Measured); "channels": {label: (RMS, unit)}}, and
    "steps": the steps' rise and settling / stock (geometric mean). Raises KeyError, ValueError on a
    malformed result (ValueError: a plant without tracking rows)."""
    name = result["variants"][0]["name"]
    out = {}
    for plant in plants:
        tag = plant_tag(plant)
        track = [r for r in result["rows"] if r["section"] == "tracking" and
                 r["label"].endswith(" RMS") and r["label"][:-len(" vx RMS")].endswith(tag) and
                 (tag or "(" not in r["label"])]
        if not track:
            raise ValueError("no tracking rows for plant %s" % plant)
        floor = [floored_ratio(r["values"][name], r["values"]["floor"], r["unit"]) for r in track]
        stock = [r["ratios"][name] for r in track]
        floor_stock = [floored_ratio(r["values"]["floor"], r["values"]["stock"], r["unit"]) for r in track]
        rms = {r["label"][:-len(" RMS")]: r["values"][name] for r in track}
        belief = {r["label"][:-len(" belief-truth RMS")]: r["values"][name] for r in result["rows"]
                  if r["section"] == "belief" and r["label"][:-len(" belief-truth RMS")] in rms}
        honest = [(belief[k] / rms[k], k.replace(tag, "") if tag else k) for k in sorted(belief)
                  if belief[k] is not None and rms[k]]
        out[plant] = {"floor": gmean(floor), "stock": gmean(stock), "floor_stock": gmean(floor_stock),
                      "channels": {k: (rms[k], r["unit"]) for k, r in zip(rms, track)},
                      "worst_belief": max(honest) if honest else (None, None)}
        for ch in ("vx", "wz"):
            vals = [v for k, v in belief.items() if k.endswith(" " + ch) and v is not None]
            out[plant]["belief_" + ch] = sum(vals) / len(vals) if vals else None
    steps = [r["ratios"][name] for r in result["rows"] if r["section"] == "steps" and r["unit"] == "s"]
    out["steps"] = gmean(steps)
    return out


def gmean(ratios):
    """plant_limits.gmean of the ratios that exist (None left out); None when none does."""
    return plant_limits.gmean([x for x in ratios if x is not None])[0]


def markdown(entries, command, threshold):
    """The results page (str): per ablation, a table of its plants, with -> without, and the
    channels that moved. ``entries``: dicts with the ablation's keys and "with", "without"
    (per_plant results, or None when the edit did not build) and "verdict"."""
    out = ["# Structural ablations", "",
           "Generated by `%s` from `dev/ablations.txt`; do not edit. Each ablation is one rule of the control "
           "law taken out (or, where its text says so, replaced by an alternative) by an edit of its source, "
           "built in a scratch copy of the repository; with and "
           "without are the same runs of `aic_compare.py` ([tools.md](../tools.md), 'Comparing variants': "
           "the scorecard's steps and the six profiles of `sim/profiles/` on each plant, noisy sensors, fixed "
           "seeds). Per plant: the geometric means over its 12 tracking channels of RMS / latency floor, "
           "RMS / stock controller and floor / stock (floored ratios), the mean RMS(belief - truth) over its "
           "profiles and its largest ratio to the channel's tracking error (the honest-belief measure of "
           "doc/active_inference.md, 'The robot model', Measured); under the table, the channels whose RMS "
           "(ground truth against the set point) moved by more than %d %%. Steps: rise and settling / "
           "stock. The floor is computed by the same build: a rule the floor's predicting servo shares "
           "(`predictGoal()`) moves it too, and floor / stock shows that." % (command, round(100 * threshold)), ""]
    for e in entries:
        out += ["## `%s`" % e["id"], "", "%s. Configuration: `%s`; the edit: `%s`." % (
            e["what"][0].upper() + e["what"][1:], e["variant"], e["file"]), ""]
        if e["without"] is None:
            out += ["**%s**" % e["verdict"], ""]
            continue
        w, wo = e["with"], e["without"]
        out += ["| plant | RMS / floor, with → without | RMS / stock, with → without | floor / stock | "
                "belief − truth vx [m/s] | belief − truth wz [rad/s] | belief − truth / error, worst channel |",
                "|---|---|---|---|---|---|---|"]
        moved = []
        for plant in e["plants"]:
            a, b = w[plant], wo[plant]
            fs = fmt(a["floor_stock"]) if fmt(a["floor_stock"]) == fmt(b["floor_stock"]) else "%s → %s" % (
                fmt(a["floor_stock"]), fmt(b["floor_stock"]))
            worst = "%s (%s) → %s (%s)" % (fmt(a["worst_belief"][0]), a["worst_belief"][1], fmt(b["worst_belief"][0]),
                                         b["worst_belief"][1])
            out.append("| %s | %s → %s | %s → %s | %s | %s → %s | %s → %s | %s |" % (
                "nominal" if plant == "default" else "`%s`" % os.path.splitext(os.path.basename(plant))[0],
                fmt(a["floor"]), fmt(b["floor"]), fmt(a["stock"]), fmt(b["stock"]), fs,
                fmt(a["belief_vx"], "%.4f"), fmt(b["belief_vx"], "%.4f"),
                fmt(a["belief_wz"], "%.4f"), fmt(b["belief_wz"], "%.4f"), worst))
            for label, (x, unit) in a["channels"].items():
                y = b["channels"].get(label, (None, unit))[0]
                if x and y and abs(y / x - 1.0) > threshold:
                    moved.append("%s %.4f → %.4f %s" % (label, x, y, unit))
        out += ["", "Steps / stock: %s → %s. Channels whose RMS moved: %s." % (
            fmt(w["steps"]), fmt(wo["steps"]), "; ".join(moved) if moved else "none"), ""]
    return "\n".join(out)


class Runner:
    """Runs the scratch copy's aic_compare.py with the scratch build's programs."""

    def __init__(self, ws, jobs, out_root):
        self.ws, self.jobs, self.out_root = ws, jobs, out_root

    def compare(self, name, variant, plants):
        """One comparison of ``variant`` (a variant line without its name) on ``plants``; the
        per_plant figures, or raises RuntimeError with the end of the tool's output."""
        out = os.path.join(self.out_root, name)
        env = dict(os.environ)
        env["CMAKE_PREFIX_PATH"] = os.pathsep.join(
            filter(None, [os.path.join(self.ws.root, "devel"), env.get("CMAKE_PREFIX_PATH")]))
        env["LD_LIBRARY_PATH"] = os.pathsep.join(
            filter(None, [os.path.join(self.ws.root, "devel", "lib"), env.get("LD_LIBRARY_PATH")]))
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [os.path.join(self.ws.src, "src"), env.get("PYTHONPATH")]))
        cmd = [sys.executable, os.path.join(self.ws.src, "scripts", "aic_compare.py"), "--variant",
               "%s=%s" % (name, variant), "--plants"] + [p if p == "default" else os.path.join(self.ws.src, p)
                                                          for p in plants] + [
               "--jobs", str(self.jobs), "--out", out, "--no-plot", "--keep-going"]
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                              env=env, cwd=self.ws.src)
        if proc.returncode != 0:
            raise RuntimeError("%s: %s" % (" ".join(cmd), proc.stdout[-2000:]))
        with open(os.path.join(out, "compare.json")) as f:
            return per_plant(json.load(f), plants)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mutants.add_list_args(ap, "ablation", "ablations.txt", "ablations")
    ap.add_argument("--threshold", type=float, default=0.05, help="a channel's move to list (fraction)")
    a = ap.parse_args(argv)
    try:
        entries = mutants.load_list(a.list, a.only, parse_list, "ablation")
        for e in entries:
            for p in e["plants"]:
                if p != "default" and not os.path.isfile(os.path.join(REPO, p)):
                    raise mutants.ListError("%s: no such plant: %s" % (e["id"], p))
    except (OSError, mutants.ListError) as e:
        print("ablations: %s" % e, file=sys.stderr)
        return 2

    ws = mutants.Workspace(a.work)
    failure = ws.prepare(TARGETS, a.jobs)
    if failure:
        print("ablations: %s" % failure, file=sys.stderr)
        return 2
    results = os.path.join(ws.root, "results")
    shutil.rmtree(results, ignore_errors=True)
    runner = Runner(ws, a.jobs, results)

    # Every comparison with the rules runs on the tree as it is, before any edit is built.
    baselines = {}
    for e in entries:
        key = (e["variant"], tuple(e["plants"]))
        try:
            if key not in baselines:
                baselines[key] = runner.compare("with_%d" % len(baselines), e["variant"], e["plants"])
        except RuntimeError as err:
            print("ablations: the comparison with the rule failed: %s" % err, file=sys.stderr)
            return 1
        e["with"] = baselines[key]
    failed = 0
    for e in entries:
        start = time.monotonic()
        path = os.path.join(ws.src, e["file"])
        with open(path) as f:
            original = f.read()
        e["without"], e["verdict"] = None, "ran"
        try:
            with open(path, "w") as f:
                f.write(mutants.apply(original, e))
            built = ws.make(TARGETS, a.jobs)
            if built.returncode != 0:
                e["verdict"] = "the edit does not build"
                print(built.stdout[-2000:])
            else:
                try:
                    e["without"] = runner.compare(e["id"], e["variant"], e["plants"])
                except RuntimeError as err:
                    e["verdict"] = "the comparison failed"
                    print(err, file=sys.stderr)
        finally:
            with open(path, "w") as f:
                f.write(original)
            ws.make(TARGETS, a.jobs)  # the next edit starts from the tree as it is
        failed += e["without"] is None
        summary = ", ".join("%s %s -> %s" % (plant_tag(p).strip(" ()") or "nominal", fmt(e["with"][p]["floor"]),
                                             fmt(e["without"][p]["floor"]) if e["without"] else "-")
                            for p in e["plants"])
        print("ablation %-26s %-24s %5.0f s  RMS / floor: %s" % (e["id"], e["verdict"], time.monotonic() - start,
                                                                  summary), flush=True)

    command = "dev/ablations.py" + (" --only " + " ".join(a.only) if a.only else "") + (
        " --markdown %s" % os.path.relpath(a.markdown, REPO) if a.markdown else "")
    page = markdown(entries, command, a.threshold)
    print(page)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(page)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
