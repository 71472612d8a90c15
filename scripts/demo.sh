#!/usr/bin/env bash
# Demo: the AIC and the Jackal's stock controller on the simulated Jackal, headless, each with
# a 0.5 m/s step from rest and with a 10 Hz planner's command stream with turns
# (sim/profiles/planner_10hz.csv). Installs what is missing, builds into the git-ignored .ws/
# (reused when run again), prints the metrics tables and the paths of the plots (PNG and PDF).
#   bash scripts/demo.sh            # results in results/demo/
#   AIC_DEMO_V=1.0 bash scripts/demo.sh                       # another step size [m/s]
#   AIC_DEMO_ARGS="--set k_a=10 --set var_y=[2,20,1e5,1e5]" bash scripts/demo.sh  # more runner args
#   AIC_DEMO_DOC=1 bash scripts/demo.sh  # also write the documented figures: doc/results/demo.txt, doc/img/
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
dev="$(dirname "$here")/dev"
source "$dev/ws_env.sh"
bash "$dev/setup_deps.sh"
bash "$dev/build.sh"
set +u  # the catkin setup scripts read unset variables
source_ws
set -u
v="${AIC_DEMO_V:-0.5}"
out="${AIC_RESULTS_DIR:-$repo/results}/demo"
mkdir -p "$out"
rc=0
for c in aic stock; do
  echo "demo: ${v} m/s step with the ${c} controller ..."
  rc=0
  # shellcheck disable=SC2086
  "$ws/devel/lib/jackal_aic/aic_experiment.py" --controller "$c" --v "$v" --hold 3 --out "$out" \
    --name "demo_${c}_step_${v}" ${AIC_DEMO_ARGS:-} > "$out/demo_${c}.log" 2>&1 || rc=$?
  [ "$rc" -eq 0 ] || { echo "demo: the ${c} run did not finish cleanly (exit $rc); its log: $out/demo_${c}.log"; tail -5 "$out/demo_${c}.log"; }
done
profile="${AIC_DEMO_PROFILE:-$repo/sim/profiles/planner_10hz.csv}"
track="$(basename "$profile" .csv)"
for c in aic stock; do
  echo "demo: the ${track} command stream with the ${c} controller ..."
  rc=0
  # shellcheck disable=SC2086
  "$ws/devel/lib/jackal_aic/aic_experiment.py" --controller "$c" --profile csv --csv "$profile" --out "$out" \
    --name "demo_${c}_${track}" ${AIC_DEMO_ARGS:-} > "$out/demo_${c}_${track}.log" 2>&1 || rc=$?
  [ "$rc" -eq 0 ] || { echo "demo: the ${c} run did not finish cleanly (exit $rc); its log: $out/demo_${c}_${track}.log"; tail -5 "$out/demo_${c}_${track}.log"; }
done
echo
{
  echo "Step response, ${v} m/s from rest (rise 10-90 %, settling +-5 %; drive cmd = the twist the wheel commands ask for):"
  /usr/bin/python3 -m jackal_aic_tools.common.summary "$out/demo_aic_step_${v}.json" "$out/demo_stock_step_${v}.json"
  echo
  echo "Tracking of ${track} (error against the set point; truth = /odom, odom = wheel odometry; drift of the /odom path):"
  /usr/bin/python3 -m jackal_aic_tools.common.summary --tracking "$out/demo_aic_${track}.json" "$out/demo_stock_${track}.json"
} | tee "$out/summary.txt"
if [ "${AIC_DEMO_DOC:-0}" = "1" ]; then
  mkdir -p "$repo/doc/results" "$repo/doc/img"
  {
    echo "# Written by: AIC_DEMO_DOC=1 bash scripts/demo.sh (config/default.yaml, sim/config/plant.yaml)"
    echo "# A ${v} m/s step from rest and the ${track} profile, node and plant in real time."
    sed "s#$repo/##g" "$out/summary.txt"
  } > "$repo/doc/results/demo.txt"
  for ext in png pdf; do  # each figure and its vector sibling
    cp "$out/demo_aic_step_${v}.$ext" "$out/demo_stock_step_${v}.$ext" "$out/demo_aic_${track}.$ext" \
      "$out/demo_stock_${track}.$ext" "$repo/doc/img/"
  done
  echo "demo: wrote doc/results/demo.txt and doc/img/demo_{aic,stock}_{step_${v},${track}}.{png,pdf}"
fi
