// The preconditioned grid LP and its revised simplex solver (grid_lp.h).
#include "msm/evaluate/grid_lp.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace msm::evaluate {

GridBasis::GridBasis(std::span<const double> grid, std::span<const std::function<double(double)>> functions,
                     const std::string& name)
    : rows_(int(functions.size()) + 1), n_(int(grid.size())), grid_(grid.begin(), grid.end()) {
  if (n_ < 2) throw std::invalid_argument("GridBasis: the grid needs at least 2 points");
  for (int i = 0; i < n_; ++i)
    if (!std::isfinite(grid[i]) || (i > 0 && !(grid[i] > grid[i - 1])))
      throw std::invalid_argument("GridBasis: grid points must be finite and strictly increasing");
  if (functions.empty() || rows_ > kMaxRows)
    throw std::invalid_argument(fmt::format("{}: a basis needs 1 to {} functions", name, kMaxRows - 1));
  if (n_ < rows_)
    throw SingularBasis(fmt::format("{}: {} functions and the constant are linearly dependent on a grid of only {} "
                                    "points (a singular moment space)",
                                    name, rows_ - 1, n_));

  using Real = long double;
  using Matrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
  Matrix a(n_, rows_);
  for (int i = 0; i < n_; ++i) {
    a(i, 0) = 1;
    for (int j = 1; j < rows_; ++j) {
      const double value = functions[j - 1](grid[i]);
      if (!std::isfinite(value))
        throw std::invalid_argument(fmt::format("{}: function {} is not finite at z = {}", name, j, grid[i]));
      a(i, j) = value;
    }
  }
  // Unit columns, so that R's diagonal measures each function's distance from the span of the
  // ones before it relative to its own size.
  for (int j = 0; j < rows_; ++j) {
    const Real norm = a.col(j).norm();
    if (norm == 0) throw SingularBasis(fmt::format("{}: function {} vanishes on the grid", name, j));
    a.col(j) /= norm;
  }
  const Eigen::HouseholderQR<Matrix> qr(a);
  const Matrix r = qr.matrixQR().topRows(rows_).template triangularView<Eigen::Upper>();
  Real largest = 0, smallest = std::numeric_limits<Real>::infinity();
  for (int j = 0; j < rows_; ++j) {
    largest = std::max(largest, std::fabs(r(j, j)));
    smallest = std::min(smallest, std::fabs(r(j, j)));
  }
  independence_ = double(smallest / largest);
  if (independence_ < kSingularTolerance)
    throw SingularBasis(fmt::format("{}: the functions are linearly dependent on the depth grid (a singular moment "
                                    "space): one lies within {:.1e} (relative) of the span of the others and the "
                                    "constant",
                                    name, independence_));
  // The LP's preconditioning: the functions at unit RMS over the grid (the columns of `a` times
  // sqrt(n)), then each grid point's column a_i = (1, b(z_i)) scaled to unit length (its variable
  // becomes w_i / d_i with d_i = 1 / |a_i|, as msm::oracle::lp_bounds does), then the rows
  // orthonormalized. None of it changes the feasible set. Grids reaching far beyond [0, 1] (the
  // cross-checks' stand-in for I = R) have columns several times longer there than on [0, 1];
  // unscaled, their tiny optimal weights make nearly singular bases.
  const Real root_n = std::sqrt(Real(n_));
  Matrix scaled = a * root_n; // (A D)^T after the loop
  scale_.resize(std::size_t(n_));
  for (int i = 0; i < n_; ++i) {
    const Real norm = scaled.row(i).norm();
    scale_[i] = double(1 / norm);
    scaled.row(i) /= norm;
  }
  const Eigen::HouseholderQR<Matrix> point_qr(scaled);
  const Matrix q = point_qr.householderQ() * Matrix::Identity(n_, rows_);
  data_.resize(std::size_t(rows_) * std::size_t(n_));
  for (int j = 0; j < rows_; ++j)
    for (int i = 0; i < n_; ++i) data_[std::size_t(j) * n_ + i] = double(q(i, j) * root_n);
}

void GridBasis::moments(std::span<const GridAtom> atoms, std::span<double> t) const {
  for (int j = 0; j < rows_; ++j) {
    const double* values = row(j);
    double sum = 0.0;
    for (const GridAtom& atom : atoms) sum += atom.weight / scale_[atom.index] * values[atom.index];
    t[j] = sum;
  }
}

// ---- GridLp -------------------------------------------------------------------------------------

namespace {
constexpr int kPhase1 = 1, kPhase2 = 2;
} // namespace

GridLp::GridLp(const GridBasis& basis)
    : basis_(basis), r_(basis.rows()), n_(basis.columns()), scale_(basis.scales()), reduced_(std::size_t(n_)),
      alpha_(std::size_t(n_)), mark_(std::size_t(n_), 0) {
  stride_ = std::max(1, (n_ - 1) / kCoarsePoints);
  // A tiny distribution over the coarse grid points (always in the working set; total weight
  // kPerturbation, jittered by a fixed low-discrepancy sequence so that no two points weigh the
  // same), added to every moment vector: the perturbed moments lie inside the moment cone of the
  // working set, where no vertex is degenerate.
  const int coarse_points = (n_ - 1) / stride_ + 1; // i = 0, stride_, ... <= n_ - 1
  for (int i = 0, count = 0; i < n_; i += stride_, ++count) {
    const double jitter = 0.5 + std::fmod(0.6180339887498949 * double(count + 1), 1.0);
    const double weight = kPerturbation * jitter / double(coarse_points);
    for (int j = 0; j < r_; ++j) perturbation_[j] += weight / scale_[i] * basis_.row(j)[i];
  }
}

double GridLp::column_entry(std::int32_t column, int j) const {
  if (column >= n_) return column - n_ == j ? sign_[j] : 0.0;
  return basis_.row(j)[column];
}

bool GridLp::is_basic(std::int32_t column) const {
  return std::find(in_basis_.begin(), in_basis_.begin() + r_, column) != in_basis_.begin() + r_;
}

void GridLp::add_working(std::int32_t column) {
  if (column < 0 || column >= n_ || mark_[column] == stamp_) return;
  mark_[column] = stamp_;
  working_.push_back(column);
}

// inverse_ = B^-1 for B = the basic columns, by Gauss-Jordan with partial pivoting in long double.
// False when a pivot is below what rounding the double columns can produce (singular basis).
bool GridLp::factorize() {
  updates_ = 0;
  const int r = r_;
  std::array<Real, kMaxRows * kMaxRows> b{};
  Real largest = 0.0L;
  for (int k = 0; k < r; ++k)
    for (int j = 0; j < r; ++j) {
      b[j * r + k] = column_entry(in_basis_[k], j);
      largest = std::max(largest, std::fabs(b[j * r + k]));
    }
  std::array<Real, kMaxRows* kMaxRows>& inv = inverse_;
  for (int j = 0; j < r; ++j)
    for (int k = 0; k < r; ++k) inv[j * r + k] = j == k ? 1.0L : 0.0L;
  const Real negligible = 1e-15L * largest;
  for (int col = 0; col < r; ++col) {
    int pivot = col;
    for (int j = col + 1; j < r; ++j)
      if (std::fabs(b[j * r + col]) > std::fabs(b[pivot * r + col])) pivot = j;
    if (!(std::fabs(b[pivot * r + col]) > negligible)) return false;
    if (pivot != col)
      for (int k = 0; k < r; ++k) {
        std::swap(b[pivot * r + k], b[col * r + k]);
        std::swap(inv[pivot * r + k], inv[col * r + k]);
      }
    const Real scale = 1.0L / b[col * r + col];
    for (int k = 0; k < r; ++k) b[col * r + k] *= scale, inv[col * r + k] *= scale;
    for (int j = 0; j < r; ++j) {
      if (j == col) continue;
      const Real factor = b[j * r + col];
      if (factor == 0.0L) continue;
      for (int k = 0; k < r; ++k) b[j * r + k] -= factor * b[col * r + k], inv[j * r + k] -= factor * inv[col * r + k];
    }
  }
  return true;
}

// B^-1 after column `leaving` of the basis gives way to a column whose B^-1 a is u (product form:
// the eta matrix of the pivot). Every kRefactorization pivots, or after a small pivot, afresh.
bool GridLp::pivot(int leaving, std::int32_t entering, const std::array<Real, kMaxRows>& u) {
  in_basis_[leaving] = entering;
  Real largest = 0.0L;
  for (int k = 0; k < r_; ++k) largest = std::max(largest, std::fabs(u[k]));
  if (++updates_ >= kRefactorization || std::fabs(u[leaving]) < 1e-6L * largest) return factorize();
  const int r = r_;
  const Real inverse_pivot = 1.0L / u[leaving];
  for (int j = 0; j < r; ++j) inverse_[leaving * r + j] *= inverse_pivot;
  for (int k = 0; k < r; ++k) {
    if (k == leaving || u[k] == 0.0L) continue;
    const Real factor = u[k];
    for (int j = 0; j < r; ++j) inverse_[k * r + j] -= factor * inverse_[leaving * r + j];
  }
  return true;
}

void GridLp::solve_primal_values(std::span<const double> t) {
  for (int k = 0; k < r_; ++k) {
    Real sum = 0.0L;
    for (int j = 0; j < r_; ++j) sum += inverse_[k * r_ + j] * Real(t[j]);
    x_[k] = sum;
  }
}

// y = c_B^T B^-1 for the phase's costs: phase 1 charges the artificials, phase 2 the grid points
// below the cutoff (their weight scale(i) v_i).
void GridLp::compute_duals(int phase, int cutoff) {
  for (int j = 0; j < r_; ++j) y_[j] = 0.0L;
  for (int k = 0; k < r_; ++k) {
    const std::int32_t column = in_basis_[k];
    const Real cost = phase == kPhase1 ? (column >= n_ ? 1.0L : 0.0L) : (column < cutoff ? Real(scale_[column]) : 0.0L);
    if (cost != 0.0L)
      for (int j = 0; j < r_; ++j) y_[j] += cost * inverse_[k * r_ + j];
  }
  for (int j = 0; j < r_; ++j) y_double_[j] = double(y_[j]);
}

double GridLp::reduced_cost(int phase, int cutoff, std::int32_t column) const {
  double d = phase == kPhase1 ? 0.0 : (column < cutoff ? scale_[column] : 0.0);
  for (int j = 0; j < r_; ++j) d -= y_double_[j] * basis_.row(j)[column];
  return d;
}

// reduced_[i] = c_i - y . column(i) over the whole grid (phase 2); 0 for basic columns.
void GridLp::price_all(int cutoff) {
  double* d = reduced_.data();
  const int n = n_;
  const int c = std::clamp(cutoff, 0, n);
  std::copy(scale_, scale_ + c, d);
  std::fill(d + c, d + n, 0.0);
  for (int j = 0; j < r_; ++j) {
    const double yj = y_double_[j];
    const double* row = basis_.row(j);
    for (int i = 0; i < n; ++i) d[i] -= yj * row[i];
  }
  for (int k = 0; k < r_; ++k)
    if (in_basis_[k] < n) d[in_basis_[k]] = 0.0;
}

// The primal simplex over the working set, from a feasible basis.
bool GridLp::primal(int phase, int cutoff, std::span<const double> t, int& iterations) {
  const int limit = 60 * r_ + 100;
  bool bland = false;
  int degenerate = 0;
  if (!factorize()) return false;
  std::array<double, kMaxRows * kMaxRows> inverse{}; // B^-1 in double, for the pricing
  for (int step = 0; step < limit; ++step) {
    solve_primal_values(t);
    for (int k = 0; k < r_; ++k)
      if (x_[k] < -kGrossInfeasibility) return false; // not a feasible basis: the primal simplex would walk
    compute_duals(phase, cutoff);
    for (int q = 0; q < r_ * r_; ++q) inverse[q] = double(inverse_[q]);
    // Pricing over the working set. Steepest edge: the largest decrease per unit length of the edge,
    // d^2 / (1 + |B^-1 a|^2) (Dantzig's most negative d picks far grid points whenever the basis is
    // nearly singular); Bland's rule after runs of degenerate pivots.
    const double threshold = phase == kPhase1 ? -kPhase1Tolerance : -kOptimalityTolerance;
    std::int32_t entering = -1;
    double best = 0.0;
    for (const std::int32_t i : working_) {
      const double d = reduced_cost(phase, cutoff, i);
      if (!(d < threshold) || is_basic(i)) continue;
      if (bland) {
        if (entering < 0 || i < entering) entering = i;
        continue;
      }
      std::array<double, kMaxRows> a{};
      for (int j = 0; j < r_; ++j) a[j] = basis_.row(j)[i];
      double edge = 1.0;
      for (int k = 0; k < r_; ++k) {
        double w = 0.0;
        for (int j = 0; j < r_; ++j) w += inverse[k * r_ + j] * a[j];
        edge += w * w;
      }
      const double score = d * d / edge;
      if (score > best) best = score, entering = i;
    }
    if (entering < 0) return true;
    std::array<double, kMaxRows> u{}, x{};
    std::array<Real, kMaxRows> exact_u{};
    double largest_u = 0.0;
    for (int k = 0; k < r_; ++k) {
      Real sum = 0.0L;
      for (int j = 0; j < r_; ++j) sum += inverse_[k * r_ + j] * Real(basis_.row(j)[entering]);
      exact_u[k] = sum;
      u[k] = double(sum);
      x[k] = double(x_[k]);
      largest_u = std::max(largest_u, std::fabs(u[k]));
    }
    // Harris: the largest step that keeps every basic value above -tolerance, then among the rows
    // that block before it the one with the largest pivot (Bland: the smallest ratio, ties to the
    // smallest column index).
    // Phase 1 takes any pivot (it must drive the artificials to zero); phase 2 refuses pivots below
    // kRelativePivotTolerance of the largest entry of u, which would make the next basis nearly
    // singular: such rows may go negative by that share of the step, which the clean-up removes.
    const double pivot_tolerance =
        phase == kPhase1 ? kPivotTolerance : std::max(kPivotTolerance, kRelativePivotTolerance * largest_u);
    double bound = std::numeric_limits<double>::infinity();
    for (int k = 0; k < r_; ++k)
      if (u[k] > pivot_tolerance) bound = std::min(bound, (std::max(x[k], 0.0) + kFeasibilityTolerance) / u[k]);
    if (!std::isfinite(bound)) return false; // unbounded: impossible for a probability distribution
    int leaving = -1;
    double step_length = 0.0;
    for (int k = 0; k < r_; ++k) {
      if (u[k] <= pivot_tolerance) continue;
      const double ratio = std::max(x[k], 0.0) / u[k];
      if (bland) {
        if (leaving < 0 || ratio < step_length || (ratio == step_length && in_basis_[k] < in_basis_[leaving]))
          leaving = k, step_length = ratio;
      } else if (ratio <= bound && (leaving < 0 || u[k] > u[leaving])) {
        leaving = k, step_length = ratio;
      }
    }
    if (!pivot(leaving, entering, exact_u)) return false;
    ++iterations;
    if (step_length < 1e-12) {
      if (++degenerate > 2 * r_) bland = true;
    } else {
      degenerate = 0;
    }
  }
  return false;
}

// The dual simplex over the whole grid from a dual feasible basis, until every basic weight is
// >= -feasibility_tolerance.
bool GridLp::dual(int cutoff, std::span<const double> t, int& iterations, double feasibility_tolerance, int limit) {
  for (int step = 0; step < limit; ++step) {
    if (!factorize()) return false;
    solve_primal_values(t);
    int leaving = -1;
    for (int k = 0; k < r_; ++k)
      if (x_[k] < -feasibility_tolerance && (leaving < 0 || x_[k] < x_[leaving])) leaving = k;
    if (leaving < 0) return true;
    compute_duals(kPhase2, cutoff);
    price_all(cutoff);
    // The pivot row, negated: alpha_i = -(row `leaving` of B^-1) . column(i); positive qualifies.
    double* alpha = alpha_.data();
    std::fill(alpha, alpha + n_, 0.0);
    for (int j = 0; j < r_; ++j) {
      const double rho = double(inverse_[leaving * r_ + j]);
      const double* row = basis_.row(j);
      for (int i = 0; i < n_; ++i) alpha[i] -= rho * row[i];
    }
    double largest_alpha = 0.0;
    for (int k = 0; k < r_; ++k)
      if (in_basis_[k] < n_) alpha[in_basis_[k]] = 0.0;
    for (int i = 0; i < n_; ++i) largest_alpha = std::max(largest_alpha, alpha[i]);
    const double pivot_tolerance = std::max(kPivotTolerance, kRelativePivotTolerance * largest_alpha);
    double bound = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n_; ++i)
      if (alpha[i] > pivot_tolerance)
        bound = std::min(bound, (std::max(reduced_[i], 0.0) + kOptimalityTolerance) / alpha[i]);
    if (!std::isfinite(bound)) return false; // the moments lie outside the grid's moment cone
    int entering = -1;
    for (int i = 0; i < n_; ++i)
      if (alpha[i] > pivot_tolerance && std::max(reduced_[i], 0.0) / alpha[i] <= bound &&
          (entering < 0 || alpha[i] > alpha[entering]))
        entering = i;
    in_basis_[leaving] = entering;
    add_working(entering);
    ++iterations;
  }
  return false;
}

// After phase 1, basic artificials sit at (about) zero: swap each for a working column with a large
// entry in its row of B^-1 A, of the sign that keeps the entering weight (x_art / entry) >= 0.
bool GridLp::drive_out_artificials(std::span<const double> t) {
  for (int k = 0; k < r_; ++k) {
    if (in_basis_[k] < n_) continue;
    if (!factorize()) return false;
    solve_primal_values(t);
    const double sign = x_[k] < 0.0L ? -1.0 : 1.0;
    std::int32_t best = -1, fallback = -1;
    double best_value = 1e-7, fallback_value = 1e-7;
    for (const std::int32_t i : working_) {
      if (is_basic(i)) continue;
      double value = 0.0;
      for (int j = 0; j < r_; ++j) value += double(inverse_[k * r_ + j]) * basis_.row(j)[i];
      if (sign * value > best_value) best = i, best_value = sign * value;
      if (std::fabs(value) > fallback_value) fallback = i, fallback_value = std::fabs(value);
    }
    if (best < 0) best = fallback;
    if (best < 0) return false;
    in_basis_[k] = best;
  }
  return factorize();
}

bool GridLp::cold_start(std::span<const double> t, int cutoff, int& iterations) {
  for (int j = 0; j < r_; ++j) {
    in_basis_[j] = n_ + j;
    sign_[j] = t[j] < 0.0 ? -1.0 : 1.0;
  }
  if (!primal(kPhase1, cutoff, t, iterations) || !factorize()) return false;
  solve_primal_values(t);
  double infeasibility = 0.0, size = 0.0;
  for (int k = 0; k < r_; ++k)
    if (in_basis_[k] >= n_) infeasibility += double(std::fabs(x_[k]));
  for (int j = 0; j < r_; ++j) size += std::fabs(t[j]);
  if (infeasibility > 1e-9 * (1.0 + size)) return false;
  return drive_out_artificials(t) && primal(kPhase2, cutoff, t, iterations);
}

// Prices the whole grid with the optimum over the working set. Adds the grid points where the
// reduced cost has a negative local minimum (where the optimal atoms want to go), with their two
// neighbours, at most 2 (m + 1) minima. Returns how many points it added: 0 means the working
// set's optimum is optimal on the whole grid.
int GridLp::extend_working_set(int cutoff) {
  compute_duals(kPhase2, cutoff);
  price_all(cutoff);
  const double* d = reduced_.data();
  std::array<std::pair<double, std::int32_t>, 2 * kMaxRows> minima{};
  int count = 0;
  for (int i = 0; i < n_; ++i) {
    if (!(d[i] < -kOptimalityTolerance) || mark_[i] == stamp_) continue;
    if ((i > 0 && d[i - 1] < d[i]) || (i + 1 < n_ && d[i + 1] < d[i])) continue;
    const std::pair<double, std::int32_t> entry{d[i], i};
    if (count < int(minima.size())) {
      minima[count++] = entry;
    } else {
      auto worst = std::max_element(minima.begin(), minima.end());
      if (entry < *worst) *worst = entry;
    }
  }
  const std::size_t before = working_.size();
  for (int k = 0; k < std::min(count, 2 * r_); ++k)
    for (int offset : {-1, 0, 1}) add_working(minima[k].second + offset);
  return int(working_.size() - before);
}

LpResult GridLp::minimize(std::span<const double> t, int cutoff, std::span<const GridAtom> support, WarmStart* warm) {
  LpResult result;
  cutoff = std::clamp(cutoff, 0, n_);
  // The working set: a coarse grid, the distribution's own points (so that the moments lie in the
  // cone of the working set), the two points at the cutoff and the warm start's basis.
  if (++stamp_ == 0) std::fill(mark_.begin(), mark_.end(), 0u), stamp_ = 1;
  working_.clear();
  for (int i = 0; i < n_; i += stride_) add_working(i);
  add_working(n_ - 1);
  for (const GridAtom& a : support) add_working(a.index);
  add_working(cutoff - 1);
  add_working(cutoff);
  if (warm && warm->valid)
    for (int k = 0; k < r_; ++k) add_working(warm->basis[k]);

  // The simplex runs on moments perturbed by a tiny distribution over the coarse grid (inside the
  // cone: no degenerate vertex), the clean-up below on the true moments.
  std::array<double, kMaxRows> perturbed_storage{};
  for (int j = 0; j < r_; ++j) perturbed_storage[j] = t[j] + perturbation_[j];
  const std::span<const double> perturbed(perturbed_storage.data(), std::size_t(r_));
  bool solved = false;
  // 1. The previous optimum, when it is still feasible: primal simplex from there.
  if (warm && warm->valid) {
    std::copy(warm->basis.begin(), warm->basis.begin() + r_, in_basis_.begin());
    if (factorize()) {
      solve_primal_values(perturbed);
      Real lowest = 0.0L;
      for (int k = 0; k < r_; ++k) lowest = std::min(lowest, x_[k]);
      if (lowest >= -kFeasibilityTolerance) solved = primal(kPhase2, cutoff, perturbed, result.iterations);
    }
  }
  // 2. Else two phases from artificial variables.
  if (!solved) {
    result.cold = true;
    solved = cold_start(perturbed, cutoff, result.iterations);
  }
  // 3. Column generation: until no grid point prices out.
  for (int round = 0; solved && round < kMaxRounds; ++round) {
    if (!factorize() || extend_working_set(cutoff) == 0) break;
    solved = primal(kPhase2, cutoff, perturbed, result.iterations);
  }
  // 4. Clean-up (grid_lp.h): dual simplex from the perturbed optimum to a basis that is strictly
  //    feasible for the true moments; where there is none, the tolerant one stands.
  if (solved) {
    const std::array<std::int32_t, kMaxRows> tolerant = in_basis_;
    int iterations = 0;
    if (!dual(cutoff, t, iterations, kCleanupTolerance, 60 * r_ + 100)) in_basis_ = tolerant;
    result.iterations += iterations;
  }
  if (!solved || !factorize()) {
    if (warm) warm->valid = false;
    result.value = std::numeric_limits<double>::quiet_NaN();
    return result;
  }
  solve_primal_values(t);
  // What the clean-up could not remove must stay within the tolerance, else no answer.
  for (int k = 0; k < r_; ++k)
    if (x_[k] < -kAcceptedInfeasibility) {
      if (warm) warm->valid = false;
      result.value = std::numeric_limits<double>::quiet_NaN();
      return result;
    }
  Real value = 0.0L;
  for (int k = 0; k < r_; ++k)
    if (in_basis_[k] < cutoff) value += Real(scale_[in_basis_[k]]) * x_[k];
  result.value = std::clamp(double(value), 0.0, 1.0);
  result.solved = true;
  if (warm) {
    std::copy(in_basis_.begin(), in_basis_.begin() + r_, warm->basis.begin());
    warm->valid = true;
  }
  return result;
}

} // namespace msm::evaluate
