#pragma once
/**
 * \file generalizer.hpp
 * \brief Generalized coordinates of a sampled signal by backward finite differences
 *        (thesis eq. 3-17 ... 3-22; Hijne 2020; doc/active_inference.md). ROS-free.
 */

#include <cstdint>

#include "jackal_aic/base/types.hpp"

namespace jackal_aic
{
namespace aic
{
/**
 * \brief Turns samples y_k (n channels) into generalized measurements
 *        y_tilde_k = [y^(0)_k, ..., y^(p)_k] (n x (p+1)).
 *
 * Recursion, per channel, with h the interval between two samples:
 *   y^(0)_k = y_k,   y^(i)_k = (y^(i-1)_k - y^(i-1)_{k-1}) / h,  i = 1..p,
 * i.e. row i of the thesis's matrix Q (eq. 3-22) applied to
 * [y_k, y^(0)_{k-1}, ..., y^(p-1)_{k-1}]. Q is rebuilt only when h changes.
 * The first sample sets order 0 and leaves the higher orders at zero.
 *
 * Bad samples never reach the division: a non-finite value, a size mismatch or a
 * non-positive / non-finite h rejects the sample, keeps the state and counts it.
 * No heap allocation in update().
 */
class Generalizer
{
public:
  /// Outcome of one update().
  enum class Status
  {
    kOk,              ///< sample accepted
    kFirstSample,     ///< accepted as the first sample: order 0 set, higher orders zero
    kNonFiniteValue,  ///< rejected: a NaN or Inf in y
    kBadInterval,     ///< rejected: h <= 0 or non-finite
    kSizeMismatch     ///< rejected: y.size() != channels()
  };

  /**
   * \param channels         number of channels n, >= 1
   * \param embedding_order  p, 1 <= p <= kMaxEmbeddingOrder
   * \throws std::invalid_argument if either is out of range
   */
  Generalizer(int channels, int embedding_order);

  /**
   * \brief Feed one sample.
   * \param y  sample, n values [channel units]
   * \param h  interval since the previous accepted sample [s], finite and > 0 (ignored for the first sample)
   * \return kOk / kFirstSample if accepted; otherwise the reason, with the state unchanged.
   */
  Status update(const Eigen::Ref<const Eigen::VectorXd>& y, double h);

  /// Current generalized signal, n x (p+1); zero before the first sample.
  const base::GeneralizedSignal& yTilde() const { return y_tilde_; }
  /// True once a first sample has been accepted.
  bool initialized() const { return initialized_; }
  /// Forget everything (state to zero, not initialized); counters kept.
  void reset();

  /// Number of channels n (rows of yTilde()).
  int channels() const { return channels_; }
  /// Embedding order p (yTilde() has p + 1 columns).
  int embeddingOrder() const { return p_; }
  /// Number of accepted samples since construction.
  std::uint64_t acceptedCount() const { return accepted_; }
  /// Number of rejected samples since construction (any reason).
  std::uint64_t rejectedCount() const { return rejected_; }

  /**
   * \brief The thesis's finite-difference matrix Q (eq. 3-22), (p+1) x (p+1).
   *
   * Row i gives y^(i)_k from the stacked vector [y_k, y^(0)_{k-1}, ..., y^(p-1)_{k-1}].
   * \param p  embedding order, 1..kMaxEmbeddingOrder
   * \param h  sample interval [s], > 0
   * \throws std::invalid_argument on a bad p or h
   */
  static Eigen::MatrixXd buildQ(int p, double h);

private:
  int channels_;
  int p_;
  bool initialized_ = false;
  double q_h_ = 0.0;  ///< h for which q_ was built
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, base::kMaxOrders, base::kMaxOrders> q_;
  base::GeneralizedSignal y_tilde_;
  base::GeneralizedSignal stacked_;  ///< scratch: [y_k, y^(0)_{k-1}, ..., y^(p-1)_{k-1}] per channel
  base::GeneralizedSignal next_;     ///< scratch: candidate y_tilde_k, committed only if finite
  std::uint64_t accepted_ = 0;
  std::uint64_t rejected_ = 0;
};

/// Human-readable name of a status, e.g. "non-finite value".
const char* toString(Generalizer::Status status);

}  // namespace aic
}  // namespace jackal_aic
