"""The driving acceptance set: the AIC against the stock controller on everything a Jackal does,
headless on the simulated Jackal's plant core (`closed_loop_run`, noisy sensors, fixed seeds).

Three parts, each AIC and stock in the same run (doc/experiments.md, 'Driving acceptance'):

- steps (STEP_CASES): 0.1, 0.5 m/s from rest, a 1 rad/s turn in place, the 0.5 m/s + 0.5 rad/s
  arc on both channels, each started at every phase of STEP_PHASES against the 50 Hz action and
  sensor clocks; settling ratio AIC / stock and overshoot of the worst phase, judged against
  STEP_BOUNDS (judge_step);
  the 0.5 m/s step and the arc also with the plant's latency and torque +-20 % and a 10 kg
  payload (ROBUST_PLANTS): no runaway, settled wherever the stock controller settles;
- turn-deficit holds (DEFICIT_TURNS): a 3 s yaw-rate hold on sim/config/variants/turn_deficit.yaml
  (a firmware whose turns fall ~0.5 rad/s short); the mean yaw-rate error over the last second
  against DEFICIT_ERROR of the command;
- tracking: every profile x plant variant of the tracking benchmark (jackal_aic_tools.common.tracking,
  scripts/aic_track.py), the RMS error of vx and wz against the set point (ground truth); the ratio
  AIC / stock per pair, judged against TRACK_PAIR_BOUND and its geometric mean against
  TRACK_GMEAN_BOUND; beside it, per pair, the latency floor (floor_rms): the error of an ideal
  servo that moves the variant's latency after it is commanded, with unlimited acceleration, and
  the geometric mean of floor / stock, below which no controller with the same latency and
  predictor of the stream can go (doc/tools.md, 'Latency floor'); and the ideal controller's
  error (jackal_aic_tools.track.plant_limits): a channel of a pair whose ideal error exceeds
  plant_limits.PLANT_LIMIT_RATIO x the floor is plant-limited, reported apart with its reason;
  the per-pair verdicts and the geometric means judge the plant-following channels only;
  with ``peer`` the classical peer (closed_loop_run --controller pi, its own YAML) on every pair
  too, its errors and geometric means against the AIC, the floor and the stock controller
  reported, not judged.

`evaluate()` runs them all and returns the figures with verdicts; `cost()` turns the figures
into the tuner's scalar (scripts/aic_tune.py --driving). Stock (and peer) runs do not depend on the
AIC's settings and are cached per process.
"""
import glob
import math
import os
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..common import closed_loop, tracking
from . import plant_limits

#: Step cases: name -> (closed_loop_run arguments, result key, which channel's figures).
STEP_CASES = {
    "0.1 m/s": (["--step", "0.1"], "segments"),
    "0.5 m/s": (["--step", "0.5"], "segments"),
    "1 rad/s turn": (["--step", "1.0", "--channel", "angular", "--hold", "4"], "segments"),
    "arc, speed": (["--step", "0.5", "--turn", "0.5"], "segments"),
    "arc, yaw": (["--step", "0.5", "--turn", "0.5"], "angular_segments"),
}
#: Settling ratio AIC / stock bound of each step case; overshoot bound [%] of every case.
STEP_BOUNDS = {"0.1 m/s": 1.0, "0.5 m/s": 0.6, "1 rad/s turn": 0.7, "arc, speed": 1.0, "arc, yaw": 1.0}
STEP_OVERSHOOT = 5.0
#: Step times after the 1 s rest [s], spread over one 20 ms period of the action and sensor clocks:
#: each step case runs at every phase, AIC and stock alike, and is judged on its worst, so a
#: bound is not met by the phase of a single run.
STEP_PHASES = (0.0, 0.0075, 0.015)
#: The wheel loop's torques -+20 % of sim/config/plant.yaml's (max_torque 8 N m, proportional_limit
#: 0.7571 N m, accel_feedforward_limit 3.243 N m), as plant overrides.
TORQUE_MINUS_20 = ["motor.max_torque=6.4", "motor.proportional_limit=0.6057", "motor.accel_feedforward_limit=2.594"]
TORQUE_PLUS_20 = ["motor.max_torque=9.6", "motor.proportional_limit=0.9085", "motor.accel_feedforward_limit=3.892"]
#: Plant variations of the stability check (plant KEY=VALUE overrides or an overlay file name).
ROBUST_PLANTS = {
    "latency -20 %": ["motor.command_delay=0.09496"],
    "latency +20 %": ["motor.command_delay=0.1424"],
    "torque -20 %": TORQUE_MINUS_20,
    "torque +20 %": TORQUE_PLUS_20,
    "payload +10 kg": "payload_10kg.yaml",
}
#: The arc step's yaw overshoot against the model's initial wheel separation (reported, table 6i of
#: the scorecard): the arc ("arc, yaw") run again at every phase with b_hat_0 = factor x the plant's
#: effective separation on that arc (arc_effective_separation).
ARC_PRIOR_FACTORS = (1.0, 1.025, 1.05)
#: Window at the end of the arc run over which the plant's effective separation is measured [s].
ARC_SEPARATION_WINDOW = 1.0
#: The body's yaw rate over the wheels' (yaw_true / yaw_odom) reads its steady value b_hat_0 / b_eff
#: once within this fraction of it: above the encoders' noise on the arc (the default's steady
#: samples lie within 1.5 %), below the prior errors of table 6i (2.5 and 5 %).
ARC_RATIO_TOLERANCE = 0.02
#: Turn-deficit holds [rad/s]; steady error bound (fraction of the command) over the last second.
DEFICIT_TURNS = (0.3, 0.5, 1.0)
DEFICIT_HOLD = 3.0
DEFICIT_ERROR = 0.02
#: Tracking bounds: every pair's AIC / stock RMS ratio (vx and wz), and their geometric mean.
TRACK_PAIR_BOUND = 1.02
TRACK_GMEAN_BOUND = 0.6
#: Honest belief: the steady mean |belief - truth| of every tracking run, per channel (closed_loop_run's
#: tracking.belief: from 0.5 s after each set-point change to the next), within this where the plant
#: follows the channel [m/s, rad/s] and within BELIEF_LIMITED_BOUND where it cannot (a plant-limited
#: channel: stalls, saturation).
BELIEF_BOUND = 0.01
BELIEF_LIMITED_BOUND = 0.03
#: Weight of the honest-belief term in cost().
BELIEF_WEIGHT = 0.5
#: End-of-profile heading: the AIC's |heading error| at the end of each tracking run (closed_loop_run's
#: path.final_heading_error, ground truth against the set point's ideal path) within the stock
#: controller's + this [rad], judged on the pairs whose plant follows both channels.
HEADING_MARGIN = 0.02
#: Stops: the largest true speed against the direction before a stop of the profile, within 1 s of
#: it (closed_loop_run's tracking.stops.reverse_speed_max), within the stock controller's + this
#: [m/s] (a robot told to stop does not move back), judged where the plant follows the speed.
STOP_MARGIN = 0.02


def default_profiles(root):
    """The tracking benchmark's profiles, sim/profiles/*.csv, sorted by name."""
    return sorted(glob.glob(os.path.join(root, "sim", "profiles", "*.csv")))


def default_variants(root):
    """'default' and every overlay of sim/config/variants/, sorted."""
    return ["default"] + sorted(glob.glob(os.path.join(root, "sim", "config", "variants", "*.yaml")))


class Runner:
    """Runs closed_loop_run for one AIC configuration (a YAML and KEY=VALUE overrides), the stock
    controller, the ideal controller and the classical peer, on one plant YAML; caches the stock and
    ideal controllers' and the peer's results (they do not depend on the AIC's settings) for its
    lifetime, and takes the ideal controller's results from ``ideal_cache`` (ideal_cache.IdealCache,
    or None) where it keeps them for the same sources, plant, overlay and profile. ``tuned``: the
    controller that plays the AIC's part, job controller "aic" ("aic", or "pi": the classical peer,
    its YAML and overrides in aic_config and aic_sets), so that the acceptance set and its cost
    judge either against the stock controller. ``peer_config``: the YAML of the classical peer
    beside it, job controller "pi" (None: closed_loop_run's default, config/classical/pi.yaml)."""

    def __init__(self, exe, aic_config, plant_config, aic_sets=(), jobs=2, ideal_cache=None, tuned="aic",
                 peer_config=None):
        self.exe, self.aic_config, self.plant_config = exe, aic_config, plant_config
        self.tuned, self.peer_config = tuned, peer_config
        self.aic_sets = list(aic_sets)
        self.jobs = max(1, jobs)
        self.ideal_cache = ideal_cache
        self._stock = {}

    def command(self, controller, args, overlay=None, plant_sets=()):
        """The argument list of one run of ``controller`` ("aic": the tuned controller with the
        runner's settings; "pi": the classical peer with peer_config; "stock"; "ideal")
        (closed_loop.command: noisy sensors, a diverged run reported and judged here, not an error;
        the ideal controller uses the ground truth and ideal sensors: plant_limits.ideal_command)."""
        if controller == "ideal":
            return plant_limits.ideal_command(self.exe, self.plant_config, args, overlay, plant_sets)
        config, sets = self.aic_config, self.aic_sets
        if controller == "aic":
            controller = self.tuned
        elif controller == "pi":
            config, sets = self.peer_config, ()
        return closed_loop.command(self.exe, controller, args, config, sets, self.plant_config,
                                   [overlay] if overlay else [], plant_sets, noise=True, keep_going=True)

    def run_all(self, jobs):
        """jobs: list of (key, controller, args, overlay, plant_sets, want_trace). Returns key ->
        (result dict, trace columns or None); stock, peer and ideal results come from the cache when
        there."""
        def one(job):
            key, controller, args, overlay, plant_sets, want_trace = job
            cache_key = (controller, tuple(args), overlay, tuple(plant_sets), want_trace)
            if controller != "aic" and cache_key in self._stock:
                return self._stock[cache_key]
            keep = controller == "ideal" and self.ideal_cache is not None and not want_trace
            if keep:
                kept_cmd = self.command(controller, list(args), overlay, plant_sets)
                kept = self.ideal_cache.get(kept_cmd)
                if kept is not None:
                    self._stock[cache_key] = (kept, None)
                    return kept, None
            trace = None
            with tempfile.TemporaryDirectory() as tmp:
                extra = []
                if want_trace:
                    extra = ["--csv", os.path.join(tmp, "trace.csv")]
                result = closed_loop.execute(self.command(controller, list(args) + extra, overlay,
                                                          plant_sets)).result
                if want_trace:
                    trace = tracking.read_columns(os.path.join(tmp, "trace.csv"))
            out = (result, trace)
            if controller != "aic":
                self._stock[cache_key] = out
            if keep:
                self.ideal_cache.put(kept_cmd, result)
            return out
        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            results = list(pool.map(one, jobs))
        return {j[0]: r for j, r in zip(jobs, results)}


def deficit_error(trace, command, hold_end, window=1.0):
    """Mean yaw-rate error (ground truth minus the command) [rad/s] over the last ``window`` s
    before ``hold_end`` (trace time, from the step)."""
    t, yaw = trace["t"], trace["yaw_true"]
    keep = (t > hold_end - window) & (t <= hold_end)
    return float(np.mean(yaw[keep]) - command)


def floor_rms(profile, latency, cache=None, accel_linear=0.0, accel_angular=0.0, period=0.0, wheels=None):
    """The latency floor of ``profile`` (CSV) for a plant with ``latency`` [s]: per channel the
    smaller RMS error of the ideal servo holding or predicting the set point
    (tracking.latency_floor), {"vx": m/s, "wz": rad/s}; its acceleration bounded by
    ``accel_linear`` [m/s^2] and ``accel_angular`` [rad/s^2], or by ``wheels`` = (A_w [rad/s^2],
    radius [m], track [m]) on each wheel, and its aim held for ``period`` [s] (all 0 and None: the
    latency floor; the wheel loop's A_w on the geometric track and the AIC's action period: the
    acceleration-bounded floor). ``cache``: a dict reused across calls. Raises tracking.TrackingError."""
    key = (profile, round(float(latency), 9), round(float(accel_linear), 9), round(float(accel_angular), 9),
           round(float(period), 9), None if wheels is None else tuple(round(float(w), 9) for w in wheels))
    if cache is not None and key in cache:
        return cache[key]
    f = tracking.latency_floor(profile, latency, accel_linear, accel_angular, period=period, wheels=wheels)
    out = {ch: min(f["hold"][ch]["rms"], f["predict"][ch]["rms"]) for ch in ("vx", "wz")}
    if cache is not None:
        cache[key] = out
    return out


def steady_yaw_rates(t, yaw_true, yaw_odom, window):
    """The steady part of an arc run's trace: the samples of its last ``window`` s (t, yaw_true,
    yaw_odom: arrays of one length, s and rad/s) and the means of the true and the wheels' yaw rate
    over them. Returns (mask, mean yaw_true, mean yaw_odom); a non-finite sample makes its mean NaN."""
    steady = t >= t[-1] - window
    return steady, float(np.mean(yaw_true[steady])), float(np.mean(yaw_odom[steady]))


def arc_effective_separation(trace, window=ARC_SEPARATION_WINDOW):
    """The model's initial wheel separation b_hat_0 and the plant's effective separation b_eff [m] of
    an AIC arc run, from its trace (closed_loop_run --csv columns t, yaw_odom, yaw_true, separation):
    b_hat_0 is the first finite value of the separation column (the learned b_hat starts there), and
    yaw_odom is the wheels' yaw rate through b_hat_0, r (omega_R - omega_L) / b_hat_0 (thesis eq. 3-1),
    so the separation that maps the wheel speeds onto the body's true yaw rate is

        b_eff = b_hat_0 x mean(yaw_odom) / mean(yaw_true)   over the last ``window`` s.

    Returns (b_hat_0, b_eff). Raises ValueError when the trace has no finite separation, or the
    window's mean |yaw_true| is below 0.05 rad/s (no turn to measure)."""
    sep = np.asarray(trace["separation"], dtype=float)
    finite = sep[np.isfinite(sep)]
    if finite.size == 0:
        raise ValueError("arc_effective_separation: the trace has no finite separation (not an AIC run?)")
    _, yaw_true, yaw_odom = steady_yaw_rates(np.asarray(trace["t"], dtype=float),
                                             np.asarray(trace["yaw_true"], dtype=float),
                                             np.asarray(trace["yaw_odom"], dtype=float), window)
    if not (abs(yaw_true) >= 0.05 and math.isfinite(yaw_odom)):
        raise ValueError("arc_effective_separation: mean yaw rate %.4f rad/s over the last %g s: no turn to "
                         "measure" % (yaw_true, window))
    b0 = float(finite[0])
    return b0, b0 * yaw_odom / yaw_true


def prior_error_seen(trace, window=ARC_SEPARATION_WINDOW, tolerance=ARC_RATIO_TOLERANCE):
    """When an arc run's trace (closed_loop_run --csv columns t, yaw_odom, yaw_true) first shows the
    model's prior separation error, and when the body's true yaw rate peaks.

    In a steady turn the body's yaw rate over the wheels' yaw rate through b_hat_0, yaw_true /
    yaw_odom, is b_hat_0 / b_eff (arc_effective_separation); in the turn's rise it is not: the body's
    yaw lags the wheels' (the scrub lag), and while the wheels' common speed changes the tyres' grip
    goes to the speed change and the body turns less than the wheels' differential says. ``seen`` is
    the first time from which that ratio, at every sample up to the last ``window`` s, is within
    ``tolerance`` of its mean over that window (a sample whose |yaw_odom| is below 10 % of that
    window's mean counts as outside): before it no reading tells b_hat_0's error from the rise, so no
    command informed by it reaches the wheels before seen + the latency.

    Returns {"seen": s, "peak": s}, trace times from the step; peak: the time of the largest
    |yaw_true|. Raises ValueError when the window's mean |yaw_true| or |yaw_odom| is below 0.05 rad/s
    (no turn to measure)."""
    t = np.asarray(trace["t"], dtype=float)
    yaw_true = np.asarray(trace["yaw_true"], dtype=float)
    yaw_odom = np.asarray(trace["yaw_odom"], dtype=float)
    after = t >= 0.0
    t, yaw_true, yaw_odom = t[after], yaw_true[after], yaw_odom[after]
    steady, true_mean, odom_mean = steady_yaw_rates(t, yaw_true, yaw_odom, window)
    if not (abs(true_mean) >= 0.05 and abs(odom_mean) >= 0.05):
        raise ValueError("prior_error_seen: mean yaw rates %.4f (true) and %.4f (wheels) rad/s over the last %g s: "
                         "no turn to measure" % (true_mean, odom_mean, window))
    turning = np.abs(yaw_odom) >= 0.1 * abs(odom_mean)
    ratio = np.where(turning, yaw_true / np.where(turning, yaw_odom, 1.0), np.nan)
    within = turning & (np.abs(ratio * odom_mean / true_mean - 1.0) <= tolerance)
    outside = np.flatnonzero(~within & ~steady)
    seen = t[outside[-1] + 1] if outside.size else t[0]
    return {"seen": float(seen), "peak": float(t[np.argmax(np.abs(yaw_true))])}


def arc_prior(runner, res):
    """Table 6i's rows: the arc step's yaw overshoot (on the gyro, the worst of STEP_PHASES) with the
    configured initial wheel separation (the runs ``res`` of evaluate(), key ("step", "arc, speed",
    phase, "aic"), the first phase's with its trace) and with b_hat_0 = each of ARC_PRIOR_FACTORS x
    the plant's effective separation on that arc (arc_effective_separation; run with ``runner``, the
    AIC's settings but wheel_separation, which a wheel_separation among the runner's own aic_sets
    would override). Returns {b_eff [m], b_hat_0 [m] (configured), rows: list of
    {separation [m], factor (separation / b_eff), overshoot [%], configured (bool), within (overshoot
    <= STEP_OVERSHOOT), seen, peak [s] (prior_error_seen on the first phase's run), latency [s] (that
    run's plant command_delay)}}. Reported, not judged: it tells how much of the arc's overshoot the
    model's prior separation decides, and whether the prior's error shows in time to act on it (seen +
    latency against peak). Raises ValueError as arc_effective_separation or prior_error_seen."""
    args, key = STEP_CASES["arc, yaw"]
    b0, b_eff = arc_effective_separation(res[("step", "arc, speed", STEP_PHASES[0], "aic")][1])

    def worst(runs):
        return max(r[key][0]["measured"]["overshoot"] or 0.0 for r in runs)

    def timing(run):  # the first phase's run: (result, trace)
        return dict(prior_error_seen(run[1]), latency=float(run[0]["command_delay"]))

    first = res[("step", "arc, speed", STEP_PHASES[0], "aic")]
    rows = [dict(timing(first), separation=b0, factor=b0 / b_eff, configured=True,
                 overshoot=worst([res[("step", "arc, speed", ph, "aic")][0] for ph in STEP_PHASES]))]
    jobs = [(("arc_prior", f, ph), "aic",
             args + ["--rest", "%.4f" % (1.0 + ph), "--aic-set", "wheel_separation=%.5f" % (f * b_eff)],
             None, (), ph == STEP_PHASES[0]) for f in ARC_PRIOR_FACTORS for ph in STEP_PHASES]
    more = runner.run_all(jobs)
    for f in ARC_PRIOR_FACTORS:
        rows.append(dict(timing(more[("arc_prior", f, STEP_PHASES[0])]), separation=f * b_eff, factor=f,
                         configured=False, overshoot=worst([more[("arc_prior", f, ph)][0] for ph in STEP_PHASES])))
    for r in rows:
        r["within"] = r["overshoot"] <= STEP_OVERSHOOT
    return {"b_eff": b_eff, "b_hat_0": b0, "rows": rows}


def judge_step(name, runs):
    """The row of step case ``name`` (a STEP_CASES key) from its runs at every phase of
    STEP_PHASES: ``runs`` is a list of (aic, stock, aic_runaways), aic and stock the "measured"
    step metrics of closed_loop_run's JSON (settling [s], overshoot [%], settled). The settling
    ratio AIC / stock is taken per phase (None where the AIC did not settle, 0.0 where only the
    stock controller did not: a step it never settles in is infinitely slow); the row holds the
    worst phase's ratio and settling times, every phase's ratio (``ratios``), the largest
    overshoot of each controller, the bound and the verdict: every phase settled within
    STEP_BOUNDS[name] x the stock controller's time, overshoot <= STEP_OVERSHOOT, no runaway.
    Raises ValueError on an empty ``runs`` or an unknown case."""
    if name not in STEP_BOUNDS or not runs:
        raise ValueError("judge_step: unknown case %r or no runs" % (name,))
    def ratio(a, s):  # None: the AIC never settles; 0.0: it settles and the stock controller never does
        if not (a["settled"] and a["settling"]):
            return None
        return a["settling"] / s["settling"] if s["settled"] and s["settling"] else 0.0

    ratios = [ratio(a, s) for a, s, _ in runs]
    worst = None if any(r is None for r in ratios) else max(range(len(runs)), key=lambda i: ratios[i])
    a_os = max(a["overshoot"] or 0.0 for a, _, _ in runs)
    s_os = max(s["overshoot"] or 0.0 for _, s, _ in runs)
    passed = bool(worst is not None and ratios[worst] <= STEP_BOUNDS[name] and a_os <= STEP_OVERSHOOT and
                  all(n == 0 for _, _, n in runs))
    pick = runs[worst] if worst is not None else runs[0]
    return {"case": name, "aic_settling": pick[0]["settling"], "stock_settling": pick[1]["settling"],
            "ratio": ratios[worst] if worst is not None else None, "ratios": ratios,
            "aic_overshoot": a_os, "stock_overshoot": s_os, "bound": STEP_BOUNDS[name], "pass": passed}


def evaluate(runner, root, profiles=None, variants=None, tracking_suite=True, steps=True, ideal=True,
             arc_prior_table=True, peer=False):
    """Run the driving acceptance set with ``runner`` (Runner); with ``ideal`` the tracking pairs'
    ideal controller too (else every channel counts as plant-following); with ``peer`` the classical
    peer too (runner's job controller "pi", its own YAML; reported, not judged). Returns a dict:
    steps: list of judge_step() rows, {case, aic_settling, stock_settling, ratio, ratios,
    aic_overshoot, stock_overshoot, bound, pass};
    robust: list of {plant, case, runaways, settled, overshoot, pass};
    arc_prior: arc_prior()'s table, or {error} where the arc gave no effective separation (with
    ``steps`` and ``arc_prior_table``; reported, not judged);
    deficit: list of {command, aic_error, stock_error, pass} (errors in rad/s);
    tracking: list of {profile, variant, aic_vx, stock_vx, vx_ratio, aic_wz, stock_wz, wz_ratio,
    floor_vx, floor_wz (floor_rms at the variant's latency), floor_vx_ratio, floor_wz_ratio (floor /
    stock), ideal_vx, ideal_wz (the ideal controller's RMS error, None without ``ideal``),
    ideal_vx_ratio, ideal_wz_ratio (ideal / floor), limited_vx, limited_wz (plant_limits.classify:
    the reason, or None where the plant follows), pass (the plant-following channels' AIC / stock
    within TRACK_PAIR_BOUND), belief_vx, belief_wz, belief_max_vx, belief_max_wz, belief_bound_vx,
    belief_bound_wz, belief_pass (judge_belief), heading_aic, heading_stock, heading_bound,
    heading_judged, heading_pass (judge_heading), stops, stop_aic, stop_stock, stop_bound,
    stop_judged, stop_pass (judge_stop); with ``peer`` peer_vx, peer_wz (the peer's RMS error)};
    over the plant-following channels: gmean {vx, wz, all} of AIC / stock (judged),
    floor_gmean of floor / stock, aic_floor_gmean of AIC / floor, stock_floor_gmean of stock / floor,
    with ``peer`` aic_peer_gmean of AIC / peer, peer_floor_gmean of peer / floor and peer_stock_gmean
    of peer / stock;
    over the plant-limited ones: limited_gmean {aic_stock, aic_floor, stock_floor, aic_ideal,
    stock_ideal, n}; pass: every verdict."""
    profiles = profiles if profiles is not None else default_profiles(root)
    variants = variants if variants is not None else default_variants(root)
    variant_dir = os.path.join(root, "sim", "config", "variants")
    jobs = []
    if steps:
        for name, (args, _) in STEP_CASES.items():
            if name == "arc, yaw":
                continue
            for phase in STEP_PHASES:
                rest = ["--rest", "%.4f" % (1.0 + phase)]
                for c in ("aic", "stock"):
                    # The arc's first AIC phase keeps its trace: table 6i's effective separation.
                    trace = name == "arc, speed" and phase == STEP_PHASES[0] and c == "aic"
                    jobs.append((("step", name, phase, c), c, args + rest, None, (), trace))
        for plant, change in ROBUST_PLANTS.items():
            overlay, sets = (os.path.join(variant_dir, change), ()) if isinstance(change, str) else (None, tuple(change))
            for name in ("0.5 m/s", "arc, speed"):
                for c in ("aic", "stock"):
                    jobs.append((("robust", plant, name, c), c, STEP_CASES[name][0], overlay, sets, False))
        deficit = os.path.join(variant_dir, "turn_deficit.yaml")
        for w in DEFICIT_TURNS:
            for c in ("aic", "stock"):
                jobs.append((("deficit", w, c), c, ["--step", str(w), "--channel", "angular", "--hold",
                                                    str(DEFICIT_HOLD)], deficit, (), True))
    if tracking_suite:
        for p in profiles:
            for v in variants:
                for c in ("aic", "stock") + (("ideal",) if ideal else ()) + (("pi",) if peer else ()):
                    jobs.append((("track", p, v, c), c, ["--profile", p], None if v == "default" else v, (), False))
    res = runner.run_all(jobs)
    out = {"steps": [], "robust": [], "deficit": [], "tracking": []}
    ok = True
    if steps:
        for name, (_, key) in STEP_CASES.items():
            base = "arc, speed" if name == "arc, yaw" else name
            runs = [(res[("step", base, phase, "aic")][0][key][0]["measured"],
                     res[("step", base, phase, "stock")][0][key][0]["measured"],
                     res[("step", base, phase, "aic")][0]["runaways"]) for phase in STEP_PHASES]
            row = judge_step(name, runs)
            ok = ok and row["pass"]
            out["steps"].append(row)
        for plant in ROBUST_PLANTS:
            for name in ("0.5 m/s", "arc, speed"):
                r = res[("robust", plant, name, "aic")][0]
                m = r["segments"][0]["measured"]
                stock_settled = res[("robust", plant, name, "stock")][0]["segments"][0]["measured"]["settled"]
                # Stable: no runaway, and settled wherever the stock controller settles (a plant that
                # cannot follow the command, e.g. a payload's arc at the torque limit, settles neither).
                passed = bool(r["runaways"] == 0 and (m["settled"] or not stock_settled))
                ok = ok and passed
                out["robust"].append({"plant": plant, "case": name, "runaways": r["runaways"], "settled": m["settled"],
                                      "stock_settled": stock_settled,
                                      "settling": m["settling"], "overshoot": m["overshoot"], "pass": passed})
        for w in DEFICIT_TURNS:
            hold_end = DEFICIT_HOLD
            ea = deficit_error(res[("deficit", w, "aic")][1], w, hold_end)
            es = deficit_error(res[("deficit", w, "stock")][1], w, hold_end)
            passed = abs(ea) <= DEFICIT_ERROR * w
            ok = ok and passed
            out["deficit"].append({"command": w, "aic_error": ea, "stock_error": es, "pass": passed})
        if arc_prior_table:
            try:
                out["arc_prior"] = arc_prior(runner, res)
            except ValueError as e:  # an arc that does not turn: nothing to measure, the rest stands
                out["arc_prior"] = {"error": str(e)}
    if tracking_suite:
        ok = judge_tracking(res, profiles, variants, ideal, out) and ok
    out["pass"] = ok
    return out


def judge_tracking(res, profiles, variants, ideal, out, floor_of=None):
    """The tracking part of evaluate(): rows, verdicts and geometric means of the runs ``res``
    (key ("track", profile, variant, controller) -> (closed_loop_run's JSON result, trace); the
    ideal controller's only with ``ideal``; the classical peer's, controller "pi", where present)
    into ``out`` (tracking, gmean, floor_gmean, aic_floor_gmean, stock_floor_gmean, limited_gmean,
    and with any peer run aic_peer_gmean, peer_floor_gmean, peer_stock_gmean over the
    plant-following channels of the pairs the peer ran; see evaluate()). ``floor_of(profile,
    latency, cache)``: the latency floor {vx, wz} (default floor_rms). Returns True when every
    judged figure passes: each pair's plant-following channels within TRACK_PAIR_BOUND, their
    geometric mean within TRACK_GMEAN_BOUND, each pair's honest belief (judge_belief),
    end-of-profile heading (judge_heading) and stops (judge_stop); the peer's figures are reported,
    not judged."""
    floor_of = floor_of or floor_rms
    ok = True
    ratios = []  # (name, channel, plant-limited, value)
    floors = {}
    for p in profiles:
        for v in variants:
            a = res[("track", p, v, "aic")][0]["tracking"]["truth"]
            s = res[("track", p, v, "stock")][0]["tracking"]["truth"]
            peer = res.get(("track", p, v, "pi"))
            q = peer[0]["tracking"]["truth"] if peer else None
            row = {"profile": os.path.splitext(os.path.basename(p))[0],
                   "variant": "default" if v == "default" else os.path.splitext(os.path.basename(v))[0]}
            floor = floor_of(p, res[("track", p, v, "stock")][0]["command_delay"], floors)
            best = plant_limits.ideal_figures(res[("track", p, v, "ideal")][0]) if ideal else None
            limited = plant_limits.classify(best, floor) if ideal else {"vx": None, "wz": None}
            passed = True
            for ch in ("vx", "wz"):
                ra = a[ch]["rms"] / s[ch]["rms"] if s[ch]["rms"] > 0 else 1.0
                rf = floor[ch] / s[ch]["rms"] if s[ch]["rms"] > 0 else 1.0
                row["aic_" + ch], row["stock_" + ch], row[ch + "_ratio"] = a[ch]["rms"], s[ch]["rms"], ra
                row["floor_" + ch], row["floor_%s_ratio" % ch] = floor[ch], rf
                row["ideal_" + ch] = best[ch] if ideal else None
                row["ideal_%s_ratio" % ch] = best[ch] / floor[ch] if ideal and floor[ch] > 0 else None
                row["limited_" + ch] = limited[ch]
                lim = limited[ch] is not None
                ratios += [("aic_stock", ch, lim, ra), ("floor_stock", ch, lim, rf)]
                if floor[ch] > 0:
                    ratios += [("aic_floor", ch, lim, a[ch]["rms"] / floor[ch]),
                               ("stock_floor", ch, lim, s[ch]["rms"] / floor[ch])]
                if ideal and best[ch] > 0:
                    ratios += [("aic_ideal", ch, lim, a[ch]["rms"] / best[ch]),
                               ("stock_ideal", ch, lim, s[ch]["rms"] / best[ch])]
                if q:
                    row["peer_" + ch] = q[ch]["rms"]
                    for name, num, den in (("aic_peer", a[ch]["rms"], q[ch]["rms"]),
                                           ("peer_floor", q[ch]["rms"], floor[ch]),
                                           ("peer_stock", q[ch]["rms"], s[ch]["rms"])):
                        if den > 0:
                            ratios.append((name, ch, lim, num / den))
                if not lim:
                    passed = passed and ra <= TRACK_PAIR_BOUND
            row["pass"] = passed
            ok = ok and passed
            ok = judge_belief(row, res[("track", p, v, "aic")][0]["tracking"]) and ok
            ok = judge_heading(row, res[("track", p, v, "aic")][0], res[("track", p, v, "stock")][0]) and ok
            ok = judge_stop(row, res[("track", p, v, "aic")][0], res[("track", p, v, "stock")][0]) and ok
            out["tracking"].append(row)

    def following(name):
        return _gmean({ch: [math.log(max(x, 1e-9)) for n, c, lim, x in ratios if n == name and c == ch and not lim]
                       for ch in ("vx", "wz")})

    out["gmean"] = following("aic_stock")
    out["floor_gmean"] = following("floor_stock")
    out["aic_floor_gmean"] = following("aic_floor")
    out["stock_floor_gmean"] = following("stock_floor")
    if any("peer_vx" in r for r in out["tracking"]):
        for name in ("aic_peer", "peer_floor", "peer_stock"):
            out[name + "_gmean"] = following(name)
    lg = {name: plant_limits.gmean([x for n, _, lim, x in ratios if n == name and lim])[0]
          for name in ("aic_stock", "aic_floor", "stock_floor", "aic_ideal", "stock_ideal")}
    lg["n"] = sum(1 for n, _, lim, _ in ratios if n == "aic_stock" and lim)
    out["limited_gmean"] = lg
    return ok and out["gmean"]["all"] <= TRACK_GMEAN_BOUND


def judge_belief(row, tracking):
    """The honest-belief verdict of one tracking row (judge_tracking's, with its limited_vx / _wz):
    adds belief_vx, belief_wz (the AIC's steady mean |belief - truth| [m/s, rad/s], closed_loop_run's
    tracking.belief), belief_max_vx, belief_max_wz (the steady maxima, reported), belief_bound_vx,
    belief_bound_wz (BELIEF_BOUND, or BELIEF_LIMITED_BOUND on a plant-limited channel), belief_settle
    (closed_loop_run's tracking.belief_settle [s]), turned_over_at (tracking.turned_over_at [s]: the
    body past 90 degrees of tilt; None: it stayed upright), belief_whole_vx, belief_whole_wz and
    belief_pass. On a run that turned the robot over the judged figures are those up to the turnover
    (tracking.belief_upright: a tumbling body's twist is no state of a wheeled robot's belief) and
    belief_whole_* the whole run's (reported); otherwise belief_whole_* equal the judged ones.
    ``tracking``: the run's JSON tracking object (without a belief, e.g. not the AIC: the row's
    belief figures are None and it passes). Returns belief_pass."""
    whole = tracking.get("belief")
    belief = tracking.get("belief_upright") or whole
    row["belief_settle"] = tracking.get("belief_settle")
    row["turned_over_at"] = tracking.get("turned_over_at")
    ok = True
    for ch in ("vx", "wz"):
        bound = BELIEF_LIMITED_BOUND if row.get("limited_" + ch) else BELIEF_BOUND
        value = belief[ch]["steady_mean_abs"] if belief and belief[ch]["samples"] > 0 else None
        row["belief_" + ch] = value
        row["belief_max_" + ch] = belief[ch]["steady_max_abs"] if value is not None else None
        row["belief_whole_" + ch] = (whole[ch]["steady_mean_abs"] if whole and whole[ch]["samples"] > 0 else
                                     None)
        row["belief_bound_" + ch] = bound
        ok = ok and (value is None or value <= bound)
    row["belief_pass"] = ok
    return ok


def judge_heading(row, aic, stock):
    """The end-of-profile heading verdict of one tracking row (judge_tracking's, with its limited_vx /
    _wz): adds heading_aic, heading_stock (closed_loop_run's path.final_heading_error of the AIC's and
    the stock controller's run [rad], signed, wrapped to (-pi, pi]; None without a path),
    heading_bound (|heading_stock| + HEADING_MARGIN [rad]), heading_judged (True where the plant
    follows both channels and both runs have a path) and heading_pass (|heading_aic| <=
    heading_bound where judged, else True). ``aic``, ``stock``: the runs' JSON results. A heading
    error near pi is a robot that ended facing the other way: spun, or tipped over (the chassis
    turned upside down). Returns heading_pass."""
    def final(result):
        path = result.get("path") or {}
        value = path.get("final_heading_error")
        return value if value is not None and math.isfinite(value) else None

    a, s = final(aic), final(stock)
    row["heading_aic"], row["heading_stock"] = a, s
    row["heading_bound"] = abs(s) + HEADING_MARGIN if s is not None else None
    row["heading_judged"] = a is not None and s is not None and not row.get("limited_vx") and not row.get("limited_wz")
    row["heading_pass"] = not row["heading_judged"] or abs(a) <= row["heading_bound"]
    return row["heading_pass"]


def judge_stop(row, aic, stock):
    """The stops' verdict of one tracking row (judge_tracking's, with its limited_vx): adds stops (the
    profile's stops: changes of the linear set point from nonzero to 0), stop_aic, stop_stock
    (closed_loop_run's tracking.stops.reverse_speed_max of the AIC's and the stock controller's run:
    the largest true speed against the direction before a stop, within its window [m/s]; None where
    the result has none), stop_bound (stop_stock + STOP_MARGIN [m/s]), stop_judged (True where the
    profile has a stop, both runs measured it and the plant follows the speed) and stop_pass
    (stop_aic <= stop_bound where judged, else True). ``aic``, ``stock``: the runs' JSON results.
    Returns stop_pass."""
    def reverse(result):
        stops = (result.get("tracking") or {}).get("stops") or {}
        value = stops.get("reverse_speed_max")
        return (stops.get("stops", 0), value if value is not None and math.isfinite(value) else None)

    n, a = reverse(aic)
    _, s = reverse(stock)
    row["stops"], row["stop_aic"], row["stop_stock"] = n, a, s
    row["stop_bound"] = s + STOP_MARGIN if s is not None else None
    row["stop_judged"] = n > 0 and a is not None and s is not None and not row.get("limited_vx")
    row["stop_pass"] = not row["stop_judged"] or a <= row["stop_bound"]
    return row["stop_pass"]


def _gmean(logs):
    """{vx, wz, all}: the geometric means of the ratios whose logs are ``logs`` {vx: [...], wz: [...]}
    (a channel without values is left out; "all" of both, 1.0 when there is none)."""
    g = {ch: math.exp(sum(v) / len(v)) for ch, v in logs.items() if v}
    n = len(logs["vx"]) + len(logs["wz"])
    g["all"] = math.exp((sum(logs["vx"]) + sum(logs["wz"])) / n) if n else 1.0
    return g


def cost(ev):
    """The tuner's scalar of evaluate()'s figures [-, lower is better]:
    the mean log ratio AIC / stock over every tracking pair and channel
    + 2 x the sum of each pair's log ratio above log(TRACK_PAIR_BOUND), / the number of pairs
    + BELIEF_WEIGHT x the sum of each pair's log(steady |belief - truth| / its bound) where above 0, /
      the number of pairs
    + per step case (its worst phase): 0.5 x max(0, log(ratio / bound)) (3 when unsettled) + 0.1
      per % of overshoot above STEP_OVERSHOOT
    + per turn-deficit hold: 5 x max(0, |error| / command - DEFICIT_ERROR)
    + 3 per robustness case that ran away or did not settle."""
    total = 0.0
    rows = ev.get("tracking", [])
    if rows:
        logs = [math.log(max(r[ch + "_ratio"], 1e-9)) for r in rows for ch in ("vx", "wz")]
        total += sum(logs) / len(logs)
        total += 2.0 * sum(max(0.0, x - math.log(TRACK_PAIR_BOUND)) for x in logs) / len(logs)
    if rows:
        total += BELIEF_WEIGHT * sum(max(0.0, math.log(max(r["belief_" + ch], 1e-9) / r["belief_bound_" + ch]))
                                     for r in rows for ch in ("vx", "wz")
                                     if r.get("belief_" + ch) is not None) / len(rows)
    for r in ev.get("steps", []):
        total += 3.0 if r["ratio"] is None else 0.5 * max(0.0, math.log(r["ratio"] / r["bound"]))
        total += 0.1 * max(0.0, (r["aic_overshoot"] or 0.0) - STEP_OVERSHOOT)
    for r in ev.get("deficit", []):
        total += 5.0 * max(0.0, abs(r["aic_error"]) / r["command"] - DEFICIT_ERROR)
    for r in ev.get("robust", []):
        total += 0.0 if r["pass"] else 3.0
    return total
