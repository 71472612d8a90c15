#pragma once
/**
 * \file step_metrics.hpp
 * \brief Step-response metrics from a sampled time series with uneven stamps (thesis ch. 5;
 *        doc/active_inference.md): rise time 10-90 %, settling time +-5 %, overshoot,
 *        steady-state error; and the integral of the absolute error (IAE). ROS-free. The one implementation used by the tests, the CLI
 *        `aic_step_metrics` and (through that CLI) the experiment scripts.
 */

#include <string>
#include <vector>

namespace jackal_aic
{
namespace analysis
{
/// What the settling band is a percentage of.
enum class SettlingBandBasis
{
  kFinalValue,  ///< band = settling_band * |target| (thesis ch. 5: "+-5 % of the final value"; default)
  kStepSize     ///< band = settling_band * |target - initial|
};

/// Definition of the step and of the metrics. The "final value" is the set point `target`,
/// not the last sample: the metrics measure how the response reaches what was asked for.
struct StepMetricsOptions
{
  double step_time = 0.0;       ///< time of the step [s] (same clock as the samples)
  double initial = 0.0;         ///< level before the step [signal units]
  double target = 0.0;          ///< set point after the step = the final value [signal units]; != initial
  double end_time = 0.0;        ///< samples after this time are ignored [s]; <= step_time means "up to the last sample"
  double rise_low = 0.1;        ///< lower rise threshold, fraction of the step (0..1)
  double rise_high = 0.9;       ///< upper rise threshold, fraction of the step (rise_low..1)
  double settling_band = 0.05;  ///< half-width of the settling band, fraction (> 0)
  /// Basis of the band. If the target is 0, kFinalValue would give an empty band; the step size is used then.
  SettlingBandBasis band_basis = SettlingBandBasis::kFinalValue;
  double steady_state_window = 0.5;  ///< steady-state error averaging window at the end [s] (> 0)
};

/// Metrics of one step. Times are measured from options.step_time; NaN where undefined.
struct StepMetrics
{
  /// Rise time [s]: time between the first crossings (linearly interpolated between samples) of
  /// initial + rise_low * step and initial + rise_high * step; NaN if the response never reaches the upper level.
  double rise_time;
  double t_rise_low;   ///< time of the rise_low crossing, from the step [s]; NaN if never crossed
  double t_rise_high;  ///< time of the rise_high crossing, from the step [s]; NaN if never crossed
  /// Settling time [s]: from the step until the response enters, for good, the band
  /// |value - target| <= band (the entry point interpolated between the last sample outside and the
  /// next one); 0 if never outside; NaN if the last sample is outside (not settled).
  double settling_time;
  bool settled;  ///< the last sample is inside the band
  double band;   ///< half-width of the settling band actually used [signal units]
  /// Overshoot [% of the step]: max over samples of (value - target) / (target - initial) * 100, >= 0.
  double overshoot_percent;
  /// Steady-state error [signal units]: time-weighted (trapezoidal) mean of target - value over the
  /// last steady_state_window seconds of the analysed samples (all of them if they span less).
  double steady_state_error;
  double steady_state_window_used;  ///< span actually averaged [s]
  /// Integral of the absolute error [signal units * s]: integral of |target - value| over the
  /// analysed samples (step_time to the last sample or end_time), the error linear between samples
  /// and integrated exactly where it changes sign. Unlike the settling time it is continuous in the
  /// response: a response that lingers at the band's edge moves it by the lingering's area, not by
  /// the lingering's duration.
  double iae;
  int samples;  ///< samples analysed (step_time <= t <= end_time)
};

/**
 * \brief Computes the step metrics of (time[k], value[k]).
 *
 * Only samples with step_time <= t (<= end_time if given) are used. Stamps need not be evenly
 * spaced but must be finite and strictly increasing.
 *
 * \param time   sample times [s]
 * \param value  sample values [signal units], same size as time
 * \throws std::invalid_argument with a clear message on: size mismatch, non-finite or
 *         non-increasing stamps, non-finite values, fewer than 2 samples in the window,
 *         target == initial, non-finite options, thresholds out of range.
 */
StepMetrics computeStepMetrics(const std::vector<double>& time, const std::vector<double>& value,
                               const StepMetricsOptions& options);

/// One-line JSON of the metrics and their options (NaN written as null), e.g. for aic_step_metrics.
std::string toJson(const StepMetrics& metrics, const StepMetricsOptions& options);

}  // namespace analysis
}  // namespace jackal_aic
