// The linear program of 2015 Algorithm 1 for one basis on one depth grid, solved fast.
//
// For grid points z_0 < .. < z_{n-1}, functions b = (f_1, .., f_m) and a distribution on the
// grid with moments t = sum_i w_i (1, b(z_i)), the sharp lower bound of Z(z < zf) is
//     G = min sum_{i < c} w_i   subject to   sum_i w_i (1, b(z_i)) = t,  w >= 0,
// c = the number of grid points below zf (the cutoff). The structure is small and fixed: m + 1
// equality rows, one column per grid point, an optimum on at most m + 1 grid points. So:
//  - GridBasis preconditions the columns once per basis and grid: the functions scaled to unit
//    RMS over the grid, then (as msm::oracle::lp_bounds does) each grid point's column scaled to
//    unit length (its variable is then the weight times that length) and the rows orthonormalized
//    (Householder QR in long double). Neither changes the
//    feasible set, and the data are well scaled whatever the functions (exp(20 z) next to z) and
//    the grid. A basis whose functions are linearly dependent on the grid (with the constant),
//    judged on the functions scaled to unit norm, has no QR of full rank: SingularBasis.
//  - GridLp is a revised simplex method on the m + 1 rows with column generation over the grid.
//    The simplex works on a working set of columns: a coarse grid (65 points), the distribution's
//    own points (so the moments are feasible there), the two points at the cutoff and the warm
//    start's basis. At its optimum the whole grid is priced once; where the reduced cost has
//    negative local minima (where the optimal atoms want to go) those points and their neighbours
//    join the working set, and the simplex continues, until no grid point prices out (measured:
//    ~2 rounds). On the full grid the simplex would move an atom by one or two grid points per
//    pivot (hundreds of pivots on 1025 points); the working set lets it jump.
//    Pricing within the working set by steepest edge (d^2 / (1 + |B^-1 a|^2)); B^-1 (at most
//    9 x 9) in long double, by Gauss-Jordan with partial pivoting and product-form updates
//    between refactorizations every 16 pivots.
//  - Degeneracy: moments of kernels holding one or two depths lie on the boundary of the moment
//    cone, where every vertex is degenerate and the simplex stalls or cycles. The simplex runs on
//    the moments plus those of a tiny distribution over the coarse grid (total weight 1e-7:
//    inside the cone), then a dual simplex on the true moments removes the negative weights that
//    this leaves (to -1e-13; where no basis is that feasible, e.g. moments that rounding moved
//    just outside the cone, the tolerant one stands if its weights are >= -1e-8). Harris' ratio
//    test (tolerance 1e-9: the weights are probabilities, the columns O(1)); Bland's rule after
//    runs of degenerate pivots.
//  - Warm start: the optimal basis of the previous fragment, when it is feasible for the new
//    moments (the layers of one texel share them), else a cold start from artificial variables
//    (two phases within the working set).
//  - A few bases are too ill-conditioned even for long double (the power moments with m = 6 on
//    1025 points: 0.7% of the LPs); minimize() then reports no solution rather than a wrong one.
// Tested against GLPK's exact (rational) mode of msm::oracle::lp_bounds on random inputs.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace msm::evaluate {

inline constexpr int kMaxRows = 9; // m + 1 for m <= 8

// The functions of a basis are linearly dependent on the grid (with the constant 1): no moment
// vector determines anything the others do not already, and the LP's rows are singular.
struct SingularBasis : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// A grid point with a probability: one atom of a depth distribution on the grid.
struct GridAtom {
  std::int32_t index = 0;
  double weight = 0.0;
};

class GridBasis {
 public:
  // `grid`: n >= 2 finite points, strictly increasing. `functions`: 1..8 functions, finite on the
  // grid. `name` is used in messages. Throws SingularBasis when the smallest diagonal entry of R
  // in the QR of the unit-scaled columns (1, f_1, .., f_m) is below kSingularTolerance times the
  // largest: one function then lies within that relative distance of the span of the others.
  GridBasis(std::span<const double> grid, std::span<const std::function<double(double)>> functions,
            const std::string& name);
  static constexpr double kSingularTolerance = 1e-9;

  int rows() const { return rows_; } // m + 1
  int columns() const { return n_; } // n, the grid points
  const std::vector<double>& grid() const { return grid_; }
  // The preconditioned column of grid point i, entry j: row(j)[i]. Rows are orthogonal with
  // squared norm n (so entries are O(1)). Its variable is v_i = w_i / scale(i): the weight of the
  // grid point is scale(i) v_i.
  const double* row(int j) const { return data_.data() + std::size_t(j) * std::size_t(n_); }
  const double* scales() const { return scale_.data(); }
  // The preconditioned moment vector of a distribution on the grid: t = sum_k (w_k / scale(index_k))
  // column(index_k).
  void moments(std::span<const GridAtom> atoms, std::span<double> t) const;
  // The smallest relative diagonal entry of R (1 for orthonormal functions, 0 for dependent).
  double independence() const { return independence_; }

 private:
  int rows_ = 0, n_ = 0;
  std::vector<double> grid_;
  std::vector<double> data_;  // rows_ x n_, row-major
  std::vector<double> scale_; // n_: 1 / |(1, b(z_i))|
  double independence_ = 0.0;
};

// The basis of the last optimum, to start the next solve from (one per chain of similar LPs).
struct WarmStart {
  std::array<std::int32_t, kMaxRows> basis{};
  bool valid = false;
};

struct LpResult {
  double value = 0.0;  // the lower bound G, clamped to [0, 1]; NaN when !solved
  bool solved = false; // false: a numerical failure (not expected for moments of a distribution on
                       // the grid; the evaluation counts them)
  int iterations = 0;  // simplex pivots, all phases
  bool cold = false;   // no usable warm start: solved from the artificial basis
};

class GridLp {
 public:
  explicit GridLp(const GridBasis& basis);
  // min sum_{i < cutoff} w_i  s.t.  sum_i w_i (1, b(z_i)) = the moments, w >= 0; cutoff in [0, n].
  // t: the preconditioned moments of `support` (GridBasis::moments), a distribution on the grid
  // (its points seed the working set, which keeps the problem feasible there). `warm` (optional)
  // is read and updated.
  LpResult minimize(std::span<const double> t, int cutoff, std::span<const GridAtom> support,
                    WarmStart* warm = nullptr);

  static constexpr double kFeasibilityTolerance = 1e-9;
  static constexpr double kOptimalityTolerance = 1e-9;
  static constexpr double kPivotTolerance = 1e-9;
  static constexpr double kRelativePivotTolerance = 1e-9;
  static constexpr double kCleanupTolerance = 1e-13;
  static constexpr double kPhase1Tolerance = 1e-13;
  static constexpr double kPerturbation = 1e-7;
  static constexpr double kGrossInfeasibility = 1e-3;
  static constexpr double kAcceptedInfeasibility = 1e-8;
  static constexpr int kCoarsePoints = 64;    // the working set's coarse grid
  static constexpr int kMaxRounds = 64;       // of column generation
  static constexpr int kRefactorization = 16; // pivots between fresh factorizations

 private:
  using Real = long double;
  bool factorize();
  bool pivot(int leaving, std::int32_t entering, const std::array<long double, kMaxRows>& u);
  void solve_primal_values(std::span<const double> t);
  void compute_duals(int phase, int cutoff);
  double reduced_cost(int phase, int cutoff, std::int32_t column) const;
  void price_all(int cutoff);
  bool primal(int phase, int cutoff, std::span<const double> t, int& iterations);
  bool dual(int cutoff, std::span<const double> t, int& iterations, double feasibility_tolerance, int limit);
  bool drive_out_artificials(std::span<const double> t);
  bool cold_start(std::span<const double> t, int cutoff, int& iterations);
  int extend_working_set(int cutoff);
  double column_entry(std::int32_t column, int j) const;
  bool is_basic(std::int32_t column) const;
  void add_working(std::int32_t column);

  const GridBasis& basis_;
  int r_ = 0, n_ = 0, stride_ = 1, updates_ = 0;
  const double* scale_;
  std::array<std::int32_t, kMaxRows> in_basis_{}; // column index, or n + j for artificial j
  std::array<double, kMaxRows> sign_{};           // artificial j's column is sign_[j] e_j
  std::array<Real, kMaxRows * kMaxRows> inverse_{};
  std::array<Real, kMaxRows> x_{}, y_{};
  std::array<double, kMaxRows> y_double_{};
  std::array<double, kMaxRows> perturbation_{};
  std::vector<double> reduced_; // n: reduced costs over the grid
  std::vector<double> alpha_;   // n: the dual simplex's pivot row
  std::vector<std::int32_t> working_;
  std::vector<std::uint32_t> mark_; // mark_[i] == stamp_: column i is in the working set
  std::uint32_t stamp_ = 0;
};

} // namespace msm::evaluate
