"""The printout of aic_scorecard.py: one table per criterion with the figures, the bound and
PASS / FAIL (jackal_aic_tools.tune.scorecard's criteria), the --doc page and the --json report."""
import contextlib
import io
import json
import os
import sys

from ..common.tables import fmt, text_table
from ..track import driving, plant_limits
from .scorecard import RISE_RATIO, ROBUST_OVERSHOOT, SETTLE_RATIO, SQUARE_OVERSHOOT, SSE_PCT, STEP_OVERSHOOT, \
    ratio, verdict


def table(title, header, rows):
    """Print one criterion's table: title, a header row and rows (lists of strings)."""
    print("\n" + title)
    print(text_table(header, rows, indent="  "))


def print_scorecard(crit, a, root):
    """Print the tables of scorecard()'s criteria (a: parsed arguments of aic_scorecard.py; root:
    the package's folder, which the printed paths are relative to)."""
    def shown(path):
        return os.path.relpath(path, root) if path.startswith(root) else path

    print("aic_scorecard: %s against the stock controller, plant %s, noisy sensors (closed_loop_run)"
          % (shown(a.aic_config),
             " + ".join(shown(f) for f in [a.plant_config] + a.plant_overlay)))
    hdr = ["step", "seed", "AIC rise/settle/os/sse", "stock rise/settle/os", "rise x", "settle x", "verdict"]

    def step_cells(r):
        return ["%.1f m/s" % r["step"], str(r["seed"]),
                "%s s / %s s / %s %% / %s %%" % (fmt(r["aic_rise"]), fmt(r["aic_settling"]),
                                                 fmt(r["aic_overshoot"], "%.1f"), fmt(r["aic_sse_pct"], "%.2f")),
                "%s s / %s s / %s %%" % (fmt(r["stock_rise"]), fmt(r["stock_settling"]),
                                         fmt(r["stock_overshoot"], "%.1f")),
                fmt(r["rise_ratio"], "%.2f"), fmt(r["settling_ratio"], "%.2f"), verdict(r["pass"]) or "(reported)"]
    table("1. Steps from rest (0.5 m/s judged: rise x <= %.2f, settle x <= %.2f, overshoot <= %g %%, sse <= %g %%)"
          % (RISE_RATIO, SETTLE_RATIO, STEP_OVERSHOOT, SSE_PCT), hdr, [step_cells(r) for r in crit["steps"]])
    table("2. 0.5 m/s step per noise seed (sensors.seed; same bounds)", hdr, [step_cells(r) for r in crit["seeds"]])
    table("3. Yaw-rate steps from rest, 8 s hold (1 rad/s judged: AIC settle <= stock settle)",
          ["step", "AIC rise/settle/os", "stock rise/settle/os", "settle x", "verdict"],
          [["%.1f rad/s" % r["step"], "%s s / %s s / %s %%" % (fmt(r["aic_rise"], "%.2f"), fmt(r["aic_settling"], "%.2f"),
                                                               fmt(r["aic_overshoot"], "%.1f")),
            "%s s / %s s / %s %%" % (fmt(r["stock_rise"], "%.2f"), fmt(r["stock_settling"], "%.2f"),
                                     fmt(r["stock_overshoot"], "%.1f")),
            fmt(ratio(r["aic_settling"], r["stock_settling"]), "%.2f"), verdict(r["pass"]) or "(reported)"]
           for r in crit["turns"]])
    table("4. Square waves, period 5 s, 2 cycles (every transition: settled, overshoot <= %g %%)" % SQUARE_OVERSHOOT,
          ["square", "transition", "AIC rise/settle/os", "stock settle/os", "verdict"],
          [["%.1f <-> %.1f" % tuple(r["square"]), "%.1f -> %.1f m/s" % (r["from"], r["to"]),
            "%s s / %s s / %s %%" % (fmt(r["aic_rise"]), fmt(r["aic_settling"]), fmt(r["aic_overshoot"], "%.1f")),
            "%s s / %s %%" % (fmt(r["stock_settling"]), fmt(r["stock_overshoot"], "%.1f")), verdict(r["pass"])]
           for r in crit["squares"]])
    table("5. Robustness, 0.5 m/s step, plant varied +-20 %% (no runaway, settled, overshoot <= %g %%)"
          % ROBUST_OVERSHOOT,
          ["plant", "AIC rise/settle/os", "stock settle", "verdict"],
          [[r["plant"], "%s s / %s s / %s %%" % (fmt(r["aic_rise"]), fmt(r["aic_settling"]),
                                                fmt(r["aic_overshoot"], "%.1f")),
            "%s s" % fmt(r["stock_settling"]), verdict(r["pass"])] for r in crit["robustness"]])
    if "driving_steps" in crit:
        print_driving(crit, shown(a.pi_config))


def print_driving(crit, peer_config):
    """Print the driving tables (criterion 6) of scorecard()'s criteria; ``peer_config``: the
    classical peer's YAML as table 6j names it (printed where the peer ran)."""
    table("6a. Driving steps at %d phases of the 50 Hz clocks (step %s ms after the rest; the worst phase "
          "judged: settling AIC / stock <= bound, overshoot <= %g %%; a phase's settle x is 0.000 where only "
          "the stock controller never settled, '-' where the AIC did not)"
          % (len(driving.STEP_PHASES), ", ".join("%g" % (1e3 * p) for p in driving.STEP_PHASES),
             driving.STEP_OVERSHOOT),
          ["case", "AIC settle/os (worst)", "stock settle/os", "settle x per phase", "worst", "bound", "verdict"],
          [[r["case"], "%s s / %s %%" % (fmt(r["aic_settling"]), fmt(r["aic_overshoot"], "%.1f")),
            "%s s / %s %%" % (fmt(r["stock_settling"]), fmt(r["stock_overshoot"], "%.1f")),
            " ".join(fmt(x, "%.3f") for x in r["ratios"]), fmt(r["ratio"], "%.3f"), "%.2f" % r["bound"],
            verdict(r["pass"])] for r in crit["driving_steps"]])
    table("6b. Turn deficit (variants/turn_deficit.yaml): mean yaw-rate error over the last 1 s of a %g s hold "
          "(|AIC| <= %g %% of the command)" % (driving.DEFICIT_HOLD, 100 * driving.DEFICIT_ERROR),
          ["command", "AIC error", "stock error", "verdict"],
          [["%.1f rad/s" % r["command"], "%+.4f rad/s" % r["aic_error"], "%+.4f rad/s" % r["stock_error"],
            verdict(r["pass"])] for r in crit["driving_deficit"]])
    table("6c. Stability on varied plants (no runaway; settled wherever the stock controller settles)",
          ["plant", "case", "AIC settle/os", "stock settled", "verdict"],
          [[r["plant"], r["case"], "%s s / %s %%" % (fmt(r["settling"]), fmt(r["overshoot"], "%.1f")),
            "yes" if r["stock_settled"] else "no", verdict(r["pass"])] for r in crit["driving_robust"]])
    rows = crit["driving_tracking"]
    limited = [(r, ch) for r in rows for ch in ("vx", "wz") if r.get("limited_" + ch)]
    n_follow = 2 * len(rows) - len(limited)

    def plant_cell(r):
        return ", ".join(ch for ch in ("vx", "wz") if r.get("limited_" + ch)) or "-"

    g = crit["driving_gmean"]
    table("6d. Tracking, RMS error against the set point (ground truth), AIC / stock <= %.2f per pair on its "
          "plant-following channels; geometric mean over the %d plant-following channels %.3f (vx %.3f, wz %.3f; "
          "bound %.2f) %s. Plant-limited channels (column 'plant limits'; 6f) are not judged"
          % (driving.TRACK_PAIR_BOUND, n_follow, g["all"], g["vx"], g["wz"], g["bound"], verdict(g["pass"])),
          ["profile", "variant", "vx AIC / stock [m/s]", "x", "wz AIC / stock [rad/s]", "x", "plant limits", "verdict"],
          [[r["profile"], r["variant"], "%.4f / %.4f" % (r["aic_vx"], r["stock_vx"]), "%.2f" % r["vx_ratio"],
            "%.4f / %.4f" % (r["aic_wz"], r["stock_wz"]), "%.2f" % r["wz_ratio"], plant_cell(r), verdict(r["pass"])]
           for r in rows])
    fg, af, sf = crit["driving_floor_gmean"], crit["driving_aic_floor_gmean"], crit["driving_stock_floor_gmean"]
    table("6e. Latency floor and ideal controller (reported). Floor: RMS error of an ideal servo that moves the "
          "variant's latency (motor.command_delay) after it is commanded, unlimited acceleration, holding or "
          "predicting the set point, whichever is lower (doc/tools.md, 'Latency floor'); no controller with that "
          "latency and predictor goes below it. Ideal: the ideal controller (closed_loop_run --controller ideal: "
          "the command learned over repeated runs, knowing the profile in advance); ideal / floor > %.2f: the "
          "plant limits the channel (doc/tools.md, 'Plant-limited pairs'). Geometric means over the %d "
          "plant-following channels: floor / stock %.3f (vx %.3f, wz %.3f), AIC / floor %.3f (vx %.3f, wz %.3f), "
          "stock / floor %.3f (vx %.3f, wz %.3f)"
          % (plant_limits.PLANT_LIMIT_RATIO, n_follow, fg["all"], fg["vx"], fg["wz"], af["all"], af["vx"], af["wz"],
             sf["all"], sf["vx"], sf["wz"]),
          ["profile", "variant", "vx floor [m/s]", "floor / stock", "AIC / floor", "ideal / floor",
           "wz floor [rad/s]", "floor / stock", "AIC / floor", "ideal / floor"],
          [[r["profile"], r["variant"], "%.4f" % r["floor_vx"], "%.2f" % r["floor_vx_ratio"],
            "%.2f" % (r["aic_vx"] / r["floor_vx"]), fmt(r.get("ideal_vx_ratio"), "%.2f") + (" *" if r.get("limited_vx") else ""),
            "%.4f" % r["floor_wz"], "%.2f" % r["floor_wz_ratio"], "%.2f" % (r["aic_wz"] / r["floor_wz"]),
            fmt(r.get("ideal_wz_ratio"), "%.2f") + (" *" if r.get("limited_wz") else "")] for r in rows])
    lg = crit["driving_limited_gmean"]
    table("6f. Plant-limited channels (reported apart, not judged): the ideal controller's RMS error > %.2f x the "
          "latency floor; the reason from the ideal run (the wheel loop's lag behind its set point, the wheels' slip "
          "against the body, the share of the time the motor torque is at its limit). Geometric means over these "
          "%d channels: AIC / stock %s, AIC / ideal %s, stock / ideal %s, AIC / floor %s"
          % (plant_limits.PLANT_LIMIT_RATIO, lg["n"], fmt(lg["aic_stock"], "%.3f"), fmt(lg["aic_ideal"], "%.3f"),
             fmt(lg["stock_ideal"], "%.3f"), fmt(lg["aic_floor"], "%.3f")),
          ["profile", "variant", "channel", "ideal RMS", "AIC / ideal", "stock / ideal", "AIC / stock",
           "reason"],
          [[r["profile"], r["variant"], ch, "%.4f %s" % (r["ideal_" + ch], plant_limits.UNITS[ch]), "%.2f" % (r["aic_" + ch] / r["ideal_" + ch]),
            "%.2f" % (r["stock_" + ch] / r["ideal_" + ch]), "%.2f" % r[ch + "_ratio"], r["limited_" + ch]]
           for r, ch in limited] or [["(none)", "", "", "", "", "", "", ""]])
    n_belief = sum(1 for r in rows if r.get("belief_pass"))
    settle = next((r["belief_settle"] for r in rows if r.get("belief_settle") is not None), None)
    table("6g. Honest belief: the AIC's steady mean |belief - truth| on every tracking run (from %s s after each "
          "change of a channel's set point to the next; closed_loop_run's tracking.belief), <= %g m/s and %g rad/s "
          "where the plant follows the channel, <= %g where it cannot (plant-limited, 6f); max: the largest steady "
          "|belief - truth| (reported). A run that turns the robot over (the body past 90 degrees of tilt, "
          "tracking.turned_over_at) is judged up to the turnover (tracking.belief_upright): a tumbling body's twist "
          "is no state of the robot's belief; 'whole run' gives the means over the whole run (reported). %d of %d "
          "runs pass"
          % (fmt(settle, "%g"), driving.BELIEF_BOUND, driving.BELIEF_BOUND, driving.BELIEF_LIMITED_BOUND, n_belief,
             len(rows)),
          ["profile", "variant", "vx mean [m/s]", "vx max [m/s]", "vx bound", "wz mean [rad/s]", "wz max [rad/s]",
           "wz bound", "turned over [s]", "whole run vx / wz", "verdict"],
          [[r["profile"], r["variant"], fmt(r.get("belief_vx"), "%.4f"), fmt(r.get("belief_max_vx"), "%.4f"),
            "%g" % r["belief_bound_vx"], fmt(r.get("belief_wz"), "%.4f"), fmt(r.get("belief_max_wz"), "%.4f"),
            "%g" % r["belief_bound_wz"], fmt(r.get("turned_over_at"), "%.2f"),
            "%s / %s" % (fmt(r.get("belief_whole_vx"), "%.4f"), fmt(r.get("belief_whole_wz"), "%.4f"))
            if r.get("turned_over_at") is not None else "-", verdict(r["belief_pass"])] for r in rows])
    print_against_stock("6h. End-of-profile heading: the AIC's |heading error| at the end of each tracking run "
                        "(ground truth against the set point's ideal path, closed_loop_run's "
                        "path.final_heading_error) <= the stock controller's + %g rad, judged where the plant "
                        "follows both channels (others reported); an error near pi is a robot that ended facing "
                        "the other way (spun, or tipped over)." % driving.HEADING_MARGIN,
                        rows, "heading", "rad", "%+.3f")
    if crit.get("driving_arc_prior"):
        print_arc_prior(crit["driving_arc_prior"])
    if "driving_aic_peer_gmean" in crit:
        print_peer(crit, peer_config)
    print_stops(rows)


def print_stops(rows):
    """Print table 6k from the tracking rows ``rows`` (driving.judge_stop's figures): per pair with a
    stop, the largest true speed against the direction before a stop, within closed_loop_run's window
    of it, of the AIC and of the stock controller, the bound and the verdict."""
    print_against_stock("6k. Stops: the AIC's largest true speed against the direction before a stop of the "
                        "profile, within 1 s of it (closed_loop_run's tracking.stops.reverse_speed_max), <= the "
                        "stock controller's + %g m/s: a robot told to stop does not move back; judged where the "
                        "plant follows the speed (others reported)." % driving.STOP_MARGIN,
                        [r for r in rows if r.get("stops")], "stop", "m/s", "%.3f",
                        lead=("stops", lambda r: "%d" % r["stops"]))


def print_against_stock(title, rows, prefix, unit, value_fmt, lead=None):
    """Print one table of tracking rows judged against the stock controller's figure plus a margin
    (driving.judge_heading, judge_stop): per row PREFIX_aic, PREFIX_stock (in ``value_fmt``, ``unit``),
    PREFIX_bound and the verdict of PREFIX_pass where PREFIX_judged, else 'reported'; ``title`` is
    followed by the count of judged rows that pass. ``lead``: an optional (header, value of a row)
    column after the variant."""
    judged = [r for r in rows if r.get(prefix + "_judged")]
    extra = [lead[0]] if lead else []
    table("%s %d of %d judged runs pass" % (title, sum(1 for r in judged if r[prefix + "_pass"]), len(judged)),
          ["profile", "variant"] + extra + ["AIC [%s]" % unit, "stock [%s]" % unit, "bound [%s]" % unit, "verdict"],
          [[r["profile"], r["variant"]] + ([lead[1](r)] if lead else []) +
           [fmt(r.get(prefix + "_aic"), value_fmt), fmt(r.get(prefix + "_stock"), value_fmt),
            fmt(r.get(prefix + "_bound"), "%.3f"),
            verdict(r[prefix + "_pass"]) if r.get(prefix + "_judged") else "reported"] for r in rows]
          or [["(none)"] + [""] * (5 + len(extra))])


def print_peer(crit, peer_config):
    """Print table 6j: the classical peer (``peer_config``: its YAML as shown) on every tracking pair of
    scorecard()'s criteria ``crit`` that it ran (rows with peer_vx, peer_wz): its RMS error, AIC / peer
    and peer / floor per channel ('*': a plant-limited channel, left out of the geometric means), and
    the geometric means driving_aic_peer_gmean, driving_peer_floor_gmean and driving_peer_stock_gmean
    over the plant-following channels. Reported, not judged."""
    rows = [r for r in crit["driving_tracking"] if "peer_vx" in r]
    n_follow = sum(1 for r in rows for ch in ("vx", "wz") if not r.get("limited_" + ch))
    ap, pf, ps = (crit["driving_%s_gmean" % n] for n in ("aic_peer", "peer_floor", "peer_stock"))

    def cells(r, ch):
        mark = " *" if r.get("limited_" + ch) else ""
        return ["%.4f" % r["peer_" + ch], fmt(ratio(r["aic_" + ch], r["peer_" + ch]), "%.2f") + mark,
                fmt(ratio(r["peer_" + ch], r["floor_" + ch]), "%.2f") + mark]
    table("6j. The classical peer (reported, not judged): PI loops on the wheel speeds and the yaw rate around the "
          "robot model's feed-forward through the latency (closed_loop_run --controller pi, %s; "
          "doc/active_inference.md, 'A classical peer'), on every tracking pair of 6d; '*': a plant-limited "
          "channel (6f), left out of the means. Geometric means over the %d plant-following channels: AIC / peer "
          "%.3f (vx %.3f, wz %.3f), peer / floor %.3f (vx %.3f, wz %.3f), peer / stock %.3f (vx %.3f, wz %.3f)"
          % (peer_config, n_follow, ap["all"], ap["vx"], ap["wz"], pf["all"], pf["vx"], pf["wz"], ps["all"],
             ps["vx"], ps["wz"]),
          ["profile", "variant", "vx peer [m/s]", "AIC / peer", "peer / floor", "wz peer [rad/s]", "AIC / peer",
           "peer / floor"],
          [[r["profile"], r["variant"]] + cells(r, "vx") + cells(r, "wz") for r in rows])


def print_arc_prior(arc):
    """Print table 6i from driving.arc_prior()'s dict ``arc``: the arc step's yaw overshoot against the
    model's initial wheel separation b_hat_0 (or, for {error}, why it was not measured)."""
    if "error" in arc:
        print("\n6i. The arc step's yaw overshoot against the model's initial wheel separation: not measured (%s)"
              % arc["error"])
        return
    table("6i. The arc step's yaw overshoot (on the gyro, worst of the %d phases; table 6a's 'arc, yaw') against "
          "the model's initial wheel separation b_hat_0 (reported): the plant's effective separation on this arc, "
          "b_eff = b_hat_0 x wheel-odometry yaw rate / true yaw rate over the last %g s, is %.4f m; the "
          "configured b_hat_0 %.4f m is %.3f x b_eff. 'error seen from': the first phase's run, the time after the "
          "step from which the true yaw rate over the wheels' stays within %g %% of its steady value b_hat_0 / b_eff "
          "(before it the turn's rise hides b_hat_0's error); a command informed by it reaches the wheels one "
          "latency later ('+ latency'), against the time of the true yaw rate's peak"
          % (len(driving.STEP_PHASES), driving.ARC_SEPARATION_WINDOW, arc["b_eff"], arc["b_hat_0"],
             arc["b_hat_0"] / arc["b_eff"], 100.0 * driving.ARC_RATIO_TOLERANCE),
          ["b_hat_0", "b_hat_0 / b_eff", "AIC yaw overshoot", "within %g %%" % driving.STEP_OVERSHOOT,
           "error seen from", "+ latency", "true yaw peak"],
          [["%.4f m%s" % (r["separation"], " (configured)" if r["configured"] else ""), "%.3f" % r["factor"],
            "%.1f %%" % r["overshoot"], "yes" if r["within"] else "no", "%.2f s" % r["seen"],
            "%.2f s" % (r["seen"] + r["latency"]), "%.2f s" % r["peak"]] for r in arc["rows"]])


def report(crit, ok, a, root):
    """Print the scorecard (print_scorecard) and its verdict; with a.doc also write it to
    doc/results/scorecard.txt (paths relative to ``root``), with a.json the figures and verdicts
    as JSON. Returns the exit status: 0 when every criterion passes (ok), else 1."""
    if a.doc:
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            print_scorecard(crit, a, root)
            print("\n%s" % ("ALL PASS" if ok else "FAIL: at least one criterion is not met"))
        text = buf.getvalue().replace(root + os.sep, "")
        sys.stdout.write(text)
        path = os.path.join(root, "doc", "results", "scorecard.txt")
        with open(path, "w") as f:
            f.write("# Written by: scripts/aic_scorecard.py %s--doc (closed_loop_run on the plant core, noisy "
                    "sensors, fixed seeds); do not edit.\n" % ("--driving " if a.driving else ""))
            f.write(text)
        print("aic_scorecard: wrote %s" % os.path.relpath(path, root))
    else:
        print_scorecard(crit, a, root)
        print("\n%s" % ("ALL PASS" if ok else "FAIL: at least one criterion is not met"))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"aic_config": a.aic_config, "plant_config": a.plant_config, "pass": ok, "criteria": crit}, f,
                      indent=1)
    return 0 if ok else 1
