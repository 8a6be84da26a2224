/// @file src/spline/banded_qr.hpp (internal)
/// @brief Sequential banded least squares by Givens rotations, shared by the fitting
/// (spline/fit.cpp) and the exact products (spline/calculus.cpp).
#pragma once
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "trivox/error.hpp"

namespace trivox::spline::detail {

/// How a rank-deficient system is reported: "<where>: ... <unknown(c)> ...; expected <expected>".
struct RankReport {
  std::string where;
  ErrorKind kind;
  std::string expected;
  std::function<std::string(int)> unknown;  // names unknown c, e.g. "control point (2, 3)"
};

/// min |A X - B| for a banded A (row j non-zero only in columns first_j .. first_j + w - 1) by
/// Givens rotations that bring one row at a time into an upper-triangular R of bandwidth w, as
/// in FITPACK (Dierckx, Curve and Surface Fitting with Splines, 1993: fpcurf, fpsurf; Lawson &
/// Hanson, Solving Least Squares Problems, Ch. 27, sequential banded accumulation): orthogonal, so the condition number is not squared
/// as in the normal equations. Rows must come in non-decreasing order of their first column:
/// then R's rows from that column on have no entry past the row's band, so rotating the row
/// through them causes no fill beyond it. R and Q^T B share an n x (w + r) band: entry (c, j) is R(c, c + j) for j < w, then (Q^T B)(c, j - w).
/// Cost O(m w (w + r)) time, O(n (w + r)) memory. (Eigen::SparseQR would fill in to O(m n) on
/// tall banded systems.)
class BandedQR {
  using Band = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;  // rows are read whole

public:
  BandedQR(int n, int w, Eigen::Index r) : n_(n), w_(w), band_(Band::Zero(n, w + r)), norm2_(static_cast<std::size_t>(n), 0.0) {}

  /// Adds the row with coefficients a (w values, of columns first .. first + w - 1, zero past n)
  /// and right-hand side b (r values).
  void add_row(int first, std::span<const double> a, const Eigen::Ref<const Eigen::RowVectorXd>& b) {
    if (first < last_first_) throw Error("internal: banded QR rows out of order", ErrorKind::failed);
    last_first_ = first;
    // Row 0 holds R's row c while the new row (row 1, shifted to start at column c) meets it.
    Eigen::Matrix<double, 2, Eigen::Dynamic> pair(2, band_.cols());
    pair.row(1) << Eigen::Map<const Eigen::RowVectorXd>(a.data(), w_), b;
    for (int j = 0; j < w_ && first + j < n_; ++j) norm2_[static_cast<std::size_t>(first + j)] += a[static_cast<std::size_t>(j)] * a[static_cast<std::size_t>(j)];
    for (int c = first; c < std::min(n_, first + w_); ++c) {
      if (pair(1, 0) != 0.0) {
        pair.row(0) = band_.row(c);
        Eigen::JacobiRotation<double> g;
        g.makeGivens(pair(0, 0), pair(1, 0));
        pair.applyOnTheLeft(0, 1, g.adjoint());
        band_.row(c) = pair.row(0);
      }
      pair.block(1, 0, 1, w_ - 1) = pair.block(1, 1, 1, w_ - 1).eval();
      pair(1, w_ - 1) = 0.0;
    }
  }

  /// X (n x r). A zero pivot of R (relative to its column of A) means that column depends on
  /// the ones before it: the system is rank deficient.
  Eigen::MatrixXd solve(const RankReport& report) const {
    int deficient = 0, first = -1;
    for (int c = 0; c < n_; ++c)
      if (!(std::abs(band_(c, 0)) > 1e-12 * std::sqrt(norm2_[static_cast<std::size_t>(c)]))) {
        ++deficient;
        if (first < 0) first = c;
      }
    if (deficient > 0)
      throw Error(report.where + ": the least-squares system has numerical rank " + std::to_string(n_ - deficient) + " for " +
                      std::to_string(n_) + " unknown control points (" + report.unknown(first) +
                      " is a combination of the ones before it); expected " + report.expected,
                  report.kind);
    std::vector<Eigen::Triplet<double>> entries;
    for (int c = 0; c < n_; ++c)
      for (int j = 0; j < w_ && c + j < n_; ++j)
        if (band_(c, j) != 0.0) entries.emplace_back(c, c + j, band_(c, j));
    Eigen::SparseMatrix<double> R(n_, n_);
    R.setFromTriplets(entries.begin(), entries.end());
    const Eigen::MatrixXd QtB = band_.rightCols(band_.cols() - w_);
    Eigen::MatrixXd X = R.triangularView<Eigen::Upper>().solve(QtB);
    if (!X.allFinite())
      throw Error(report.where + ": the least-squares solve produced non-finite control points; expected a "
                  "well-conditioned system", ErrorKind::failed);
    return X;
  }

private:
  int n_, w_;
  int last_first_ = 0;
  Band band_;
  std::vector<double> norm2_;  // squared column norms of A
};

}  // namespace trivox::spline::detail
