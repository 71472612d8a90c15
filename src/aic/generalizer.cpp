/**
 * \file generalizer.cpp
 * \brief Finite-difference generalized coordinates (thesis eq. 3-17 ... 3-22; Hijne 2020).
 */
#include "jackal_aic/aic/generalizer.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace jackal_aic
{
namespace aic
{
namespace
{
/// Fills q (resized to (p+1) x (p+1)) with the thesis's Q (eq. 3-22) for interval h.
/// Row i expands the recursion y^(i)_k = (y^(i-1)_k - y^(i-1)_{k-1}) / h:
///   y^(i)_k = y_k / h^i - sum_{j=0}^{i-1} y^(j)_{k-1} / h^(i-j).
template <typename Matrix>
void fillQ(int p, double h, Matrix* q)
{
  const int n = p + 1;
  q->setZero(n, n);
  (*q)(0, 0) = 1.0;
  for (int i = 1; i < n; ++i)
  {
    (*q)(i, 0) = std::pow(h, -i);
    for (int j = 0; j < i; ++j)
    {
      (*q)(i, j + 1) = -std::pow(h, -(i - j));
    }
  }
}
}  // namespace

Generalizer::Generalizer(int channels, int embedding_order) : channels_(channels), p_(embedding_order)
{
  if (channels < 1)
  {
    throw std::invalid_argument("Generalizer: channels = " + std::to_string(channels) + " (allowed: >= 1)");
  }
  if (embedding_order < 1 || embedding_order > base::kMaxEmbeddingOrder)
  {
    throw std::invalid_argument("Generalizer: embedding_order = " + std::to_string(embedding_order) + " (allowed: 1.." +
                                std::to_string(base::kMaxEmbeddingOrder) + ")");
  }
  q_.setZero(p_ + 1, p_ + 1);
  y_tilde_.setZero(channels_, p_ + 1);
  stacked_.setZero(channels_, p_ + 1);
  next_.setZero(channels_, p_ + 1);
}

Eigen::MatrixXd Generalizer::buildQ(int p, double h)
{
  if (p < 1 || p > base::kMaxEmbeddingOrder)
  {
    throw std::invalid_argument("Generalizer::buildQ: p = " + std::to_string(p) + " (allowed: 1.." +
                                std::to_string(base::kMaxEmbeddingOrder) + ")");
  }
  if (!(std::isfinite(h) && h > 0.0))
  {
    throw std::invalid_argument("Generalizer::buildQ: h = " + std::to_string(h) + " (allowed: > 0 and finite)");
  }
  Eigen::MatrixXd q;
  fillQ(p, h, &q);
  return q;
}

Generalizer::Status Generalizer::update(const Eigen::Ref<const Eigen::VectorXd>& y, double h)
{
  if (y.size() != channels_)
  {
    ++rejected_;
    return Status::kSizeMismatch;
  }
  if (!y.allFinite())
  {
    ++rejected_;
    return Status::kNonFiniteValue;
  }
  if (!initialized_)
  {
    y_tilde_.setZero();
    y_tilde_.col(0) = y;
    initialized_ = true;
    ++accepted_;
    return Status::kFirstSample;
  }
  if (!(std::isfinite(h) && h > 0.0))
  {
    ++rejected_;
    return Status::kBadInterval;
  }
  if (h != q_h_)
  {
    fillQ(p_, h, &q_);
    q_h_ = h;
  }
  // stacked = [y_k, y^(0)_{k-1}, ..., y^(p-1)_{k-1}] per channel (rows).
  stacked_.col(0) = y;
  stacked_.rightCols(p_) = y_tilde_.leftCols(p_);
  // y_tilde_k = stacked * Q^T into a scratch, written as explicit loops (tiny sizes, no temporaries).
  const int n = p_ + 1;
  for (int c = 0; c < channels_; ++c)
  {
    for (int i = 0; i < n; ++i)
    {
      double acc = 0.0;
      for (int j = 0; j <= i; ++j)  // Q is lower triangular
      {
        acc += q_(i, j) * stacked_(c, j);
      }
      next_(c, i) = acc;
    }
  }
  if (!next_.allFinite())
  {
    // Only reachable with an h so small that 1/h^p overflows: reject, state untouched.
    ++rejected_;
    return Status::kBadInterval;
  }
  y_tilde_ = next_;
  ++accepted_;
  return Status::kOk;
}

void Generalizer::reset()
{
  initialized_ = false;
  y_tilde_.setZero();
  stacked_.setZero();
}

const char* toString(Generalizer::Status status)
{
  switch (status)
  {
    case Generalizer::Status::kOk:
      return "ok";
    case Generalizer::Status::kFirstSample:
      return "first sample";
    case Generalizer::Status::kNonFiniteValue:
      return "non-finite value";
    case Generalizer::Status::kBadInterval:
      return "bad interval";
    case Generalizer::Status::kSizeMismatch:
      return "size mismatch";
  }
  return "unknown";
}

}  // namespace aic
}  // namespace jackal_aic
