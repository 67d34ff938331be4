// 2015 Algorithm 1 (the general moment problem on a finite grid) as two GLPK linear programs.
#include "msm/oracle/lp_oracle.h"

#include <Eigen/Dense>
#include <glpk.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace msm::oracle {
namespace {

void require(bool condition, const char* message) {
  if (!condition) throw std::invalid_argument(message);
}

// GLPK keeps an environment per thread, created on first use and never freed unless asked. One
// that this call creates, this call frees (then nothing of GLPK's outlives a thread that only used
// lp_bounds); one that existed before may hold the caller's GLPK objects and stays.
struct GlpkEnvironment {
  bool created = glp_init_env() == 0; // 1: existed already
  ~GlpkEnvironment() {
    if (created) glp_free_env();
  }
};

// Turns GLPK's terminal output off for this thread's GLPK environment and restores it after.
struct QuietGlpk {
  int previous = glp_term_out(GLP_OFF);
  ~QuietGlpk() { glp_term_out(previous); }
};

struct DeleteProblem {
  void operator()(glp_prob* problem) const { glp_delete_prob(problem); }
};

std::string glpk_failure(const char* routine, int code) {
  const char* name = code == GLP_EBADB    ? "invalid basis"
                     : code == GLP_ESING  ? "singular basis matrix"
                     : code == GLP_ECOND  ? "ill-conditioned basis matrix"
                     : code == GLP_EBOUND ? "bad bounds"
                     : code == GLP_EFAIL  ? "solver failure"
                     : code == GLP_EITLIM ? "iteration limit"
                     : code == GLP_ETMLIM ? "time limit"
                     : code == GLP_ENODFS ? "no dual feasible solution"
                                          : "error";
  return std::string(routine) + " failed: " + name + " (" + std::to_string(code) + ")";
}

std::string scientific(long double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", double(x));
  return text;
}

// One way of running GLPK's simplex.
struct Attempt {
  bool presolve, scaling;
  double tolerance; // tol_bnd and tol_dj
  int ratio_test;   // GLP_RT_HAR or GLP_RT_STD
  const char* name;
};

// Runs the simplex, from the current basis when `warm` (else from GLPK's advanced basis), and
// says why its result is unusable, or "" when GLPK reports an optimum.
std::string simplex(glp_prob* problem, const Attempt& attempt, bool warm, int iteration_limit) {
  if (attempt.scaling)
    glp_scale_prob(problem, GLP_SF_AUTO);
  else
    glp_unscale_prob(problem);
  glp_smcp parameters;
  glp_init_smcp(&parameters);
  parameters.msg_lev = GLP_MSG_OFF;
  parameters.presolve = attempt.presolve ? GLP_ON : GLP_OFF;
  parameters.tol_bnd = parameters.tol_dj = attempt.tolerance;
  parameters.it_lim = iteration_limit;
  parameters.r_test = attempt.ratio_test;
  if (!warm && !attempt.presolve) glp_adv_basis(problem, 0);
  const int code = glp_simplex(problem, &parameters);
  // With presolve GLPK reports infeasibility as an error code, without it as a status.
  if (code == GLP_ENOPFS || (code == 0 && glp_get_status(problem) == GLP_NOFEAS)) return "infeasible";
  if (code != 0) return glpk_failure("glp_simplex", code);
  return glp_get_status(problem) == GLP_OPT
             ? ""
             : "not optimal (GLPK status " + std::to_string(glp_get_status(problem)) + ")";
}

using Real = long double;
using Matrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
using Vector = Eigen::Matrix<Real, Eigen::Dynamic, 1>;

// The LP in preconditioned form. The feasible set {w >= 0 : A w = t} does not change when the
// columns are scaled by d_i > 0 (w_i = d_i v_i) or the rows are combined by an invertible T. With
// d_i = 1 / |A_i| and T = R^-T from (A D)^T = Q R, the rows T A D = Q^T are orthonormal and the
// columns no longer than 1: for the power basis on a wide grid (z^8 = 1e24 at z = 1e3 next to
// z^8 < 1 on [0, 1]) this is the difference between GLPK's tolerances being relative to the data
// or swamping them (measured, m = 8 on wide_grid(0, 1): optima violating the rows by 20, against
// 1e-19 after preconditioning).
struct Preconditioned {
  Matrix rows;             // Q^T, rows x columns
  Vector target;           // T t
  Vector band;             // |T| |t| eps: what rounding t to double can move T t by
  std::vector<Real> scale; // d_i
};

Preconditioned precondition(const Matrix& a, const Vector& target) {
  const Eigen::Index rows = a.rows(), columns = a.cols();
  Preconditioned p;
  Matrix scaled_t(columns, rows); // (A D)^T
  for (Eigen::Index i = 0; i < columns; ++i) {
    p.scale.push_back(1 / a.col(i).norm());
    scaled_t.row(i) = a.col(i).transpose() * p.scale.back();
  }
  const Eigen::HouseholderQR<Matrix> qr(scaled_t);
  const Matrix r = qr.matrixQR().topRows(rows).triangularView<Eigen::Upper>();
  const Real largest = r.diagonal().cwiseAbs().maxCoeff();
  Matrix t = Matrix::Identity(rows, rows);
  if (r.diagonal().cwiseAbs().minCoeff() <= 1e-13L * largest) {
    // The basis functions are linearly dependent on the grid: T would not exist. Leave the rows
    // alone (GLPK copes with redundant equality rows) and keep only the column scaling.
    p.rows = scaled_t.transpose();
  } else {
    p.rows = (qr.householderQ() * Matrix::Identity(columns, rows)).transpose();
    t = r.transpose().triangularView<Eigen::Lower>().solve(t);
  }
  p.target = t * target;
  p.band = t.cwiseAbs() * target.cwiseAbs() * Real(0x1p-53L);
  return p;
}

// GLPK's final basis, re-solved and checked in long double on the preconditioned data.
struct Checked {
  std::vector<Real> w;     // the optimal weights, w = d v
  Real residual = 0;       // max_j |sum_i A_ji w_i - t_j| / (1 + |t_j|), original rows
  Real negative = 0;       // -min(0, min_i v_i), in the preconditioned variables
  Real dual_violation = 0; // largest reduced cost of the wrong sign (preconditioned units)
  bool acceptable(Real tolerance) const {
    return residual <= tolerance && negative <= tolerance && dual_violation <= tolerance;
  }
};

// The basic columns S solve rows_S v_S = target; y from rows_S^T y = c_S gives the reduced costs
// c_i - rows_i^T y, which must be >= 0 (minimum) or <= 0 (maximum) for the basis to be optimal.
// GLPK's own values when a row's slack is basic (a degenerate basis has fewer basic columns).
Checked check(glp_prob* problem, const Preconditioned& p, const Matrix& a, const Vector& target,
              const std::vector<Real>& objective, bool minimize) {
  const Eigen::Index rows = p.rows.rows(), columns = p.rows.cols();
  Checked c;
  c.w.assign(columns, 0);
  std::vector<Eigen::Index> basic;
  std::vector<Real> v(columns), reduced(columns);
  for (Eigen::Index i = 0; i < columns; ++i) {
    v[i] = glp_get_col_prim(problem, int(i) + 1);
    reduced[i] = glp_get_col_dual(problem, int(i) + 1);
    if (glp_get_col_stat(problem, int(i) + 1) == GLP_BS) basic.push_back(i);
  }
  if (Eigen::Index(basic.size()) == rows) {
    Matrix system(rows, rows);
    Vector cost(rows);
    for (Eigen::Index k = 0; k < rows; ++k) system.col(k) = p.rows.col(basic[k]), cost[k] = objective[basic[k]];
    const Eigen::FullPivLU<Matrix> lu(system);
    if (lu.isInvertible()) {
      const Vector vb = lu.solve(p.target);
      const Vector y = Eigen::FullPivLU<Matrix>(system.transpose()).solve(cost);
      std::fill(v.begin(), v.end(), 0);
      for (Eigen::Index k = 0; k < rows; ++k) v[basic[k]] = vb[k];
      for (Eigen::Index i = 0; i < columns; ++i) reduced[i] = objective[i] - p.rows.col(i).dot(y);
    }
  }
  for (Eigen::Index i = 0; i < columns; ++i) {
    c.w[i] = p.scale[i] * v[i];
    c.negative = std::max(c.negative, -v[i]);
    c.dual_violation = std::max(c.dual_violation, minimize ? -reduced[i] : reduced[i]);
  }
  for (Eigen::Index j = 0; j < rows; ++j) {
    Real moment = 0;
    for (Eigen::Index i = 0; i < columns; ++i) moment += a(j, i) * c.w[i];
    c.residual = std::max(c.residual, std::fabs(moment - target[j]) / (1 + std::fabs(target[j])));
  }
  return c;
}

LpDistribution distribution(const std::vector<Real>& w, const std::vector<double>& grid) {
  std::vector<std::pair<double, double>> atoms;
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (w[i] != 0) atoms.emplace_back(grid[i], double(w[i])); // tiny negatives too: the bounds include them
  std::sort(atoms.begin(), atoms.end());
  LpDistribution result;
  for (const auto& [z, weight] : atoms) result.support.push_back(z), result.weights.push_back(weight);
  return result;
}

} // namespace

std::vector<double> Basis::operator()(double z) const {
  std::vector<double> out(size);
  eval(z, out);
  return out;
}

Basis power_basis(int m) {
  require(m >= 1, "power_basis: m >= 1");
  return {"power" + std::to_string(m), std::size_t(m), [](double z, std::span<double> out) {
            double power = 1;
            for (double& value : out) value = power *= z;
          }};
}

Basis trigonometric_basis(int pairs) {
  require(pairs >= 1, "trigonometric_basis: pairs >= 1");
  return {"trigonometric" + std::to_string(pairs), std::size_t(2 * pairs), [](double z, std::span<double> out) {
            for (std::size_t k = 0; 2 * k < out.size(); ++k) {
              const double angle = 2 * std::numbers::pi * double(k + 1) * z;
              out[2 * k] = std::sin(angle);
              out[2 * k + 1] = std::cos(angle);
            }
          }};
}

Basis exponential_basis(std::vector<double> exponents) {
  require(!exponents.empty(), "exponential_basis: at least one exponent");
  const std::size_t size = exponents.size();
  return {"exponential", size, [exponents = std::move(exponents)](double z, std::span<double> out) {
            for (std::size_t j = 0; j < out.size(); ++j) out[j] = std::exp(exponents[j] * z);
          }};
}

Basis exponential_basis(double c, int m) {
  require(m >= 1, "exponential_basis: m >= 1");
  std::vector<double> exponents;
  for (int j = 1; j <= m; ++j) exponents.push_back(j * c);
  return exponential_basis(std::move(exponents));
}

Basis custom_basis(std::string name, std::vector<std::function<double(double)>> functions) {
  require(!functions.empty() && std::all_of(functions.begin(), functions.end(), [](const auto& f) { return bool(f); }),
          "custom_basis: non-empty functions");
  const std::size_t size = functions.size();
  return {std::move(name), size, [functions = std::move(functions)](double z, std::span<double> out) {
            for (std::size_t j = 0; j < out.size(); ++j) out[j] = functions[j](z);
          }};
}

std::vector<double> expectations(const Mixture& distribution, const Basis& basis) {
  return distribution.expectations(basis.eval, basis.size);
}

std::vector<double> uniform_grid(double a, double b, std::size_t n) {
  require(std::isfinite(a) && std::isfinite(b) && a < b && n >= 2, "uniform_grid: a < b, n >= 2");
  std::vector<double> grid(n);
  for (std::size_t i = 0; i < n; ++i) grid[i] = a + (b - a) * double(i) / double(n - 1);
  grid.back() = b;
  return grid;
}

std::vector<double> wide_grid(double a, double b, std::size_t inner, double reach, double growth) {
  require(reach > 0 && growth >= 1, "wide_grid: reach > 0, growth >= 1");
  std::vector<double> grid = uniform_grid(a, b, inner);
  const double h = (b - a) / double(inner - 1);
  double step = h;
  for (double left = a, right = b; right - b < reach;) {
    step *= growth;
    left -= step, right += step;
    grid.push_back(left), grid.push_back(right);
  }
  std::sort(grid.begin(), grid.end());
  return grid;
}

std::vector<double> merge_grids(std::span<const double> a, std::span<const double> b) {
  std::vector<double> grid(a.begin(), a.end());
  grid.insert(grid.end(), b.begin(), b.end());
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  return grid;
}

// long: one GLPK problem from its columns to its checked minimum and maximum; the parts share the
// problem, its scaling and the state of the solver attempts.
LpBounds lp_bounds(std::span<const double> grid_in, const Basis& basis, std::span<const double> b, double zf,
                   const LpOptions& options) {
  require(!grid_in.empty() && basis.size >= 1 && bool(basis.eval) && b.size() == basis.size,
          "lp_bounds: non-empty grid, b.size() == basis.size");
  require(std::isfinite(zf) && std::all_of(b.begin(), b.end(), [](double x) { return std::isfinite(x); }) &&
              std::all_of(grid_in.begin(), grid_in.end(), [](double x) { return std::isfinite(x); }),
          "lp_bounds: finite grid, b and zf");
  std::vector<double> grid(grid_in.begin(), grid_in.end());
  if (std::find(grid.begin(), grid.end(), zf) == grid.end()) grid.push_back(zf);
  const int rows = int(basis.size) + 1, columns = int(grid.size());

  // Algorithm 1, step 2: columns (1, b(z_i)), target (1, b).
  Matrix a(rows, columns);
  Vector target(rows);
  std::vector<double> column(basis.size);
  for (int i = 0; i < columns; ++i) {
    basis.eval(grid[i], column);
    a(0, i) = 1;
    for (int j = 1; j < rows; ++j) {
      require(std::isfinite(column[j - 1]), "lp_bounds: basis values must be finite on the grid");
      a(j, i) = column[j - 1];
    }
  }
  target[0] = 1;
  for (int j = 1; j < rows; ++j) target[j] = b[j - 1];
  const Preconditioned p = precondition(a, target);

  // 1-based triplets, as GLPK wants them; zeros left out (GLPK stores the matrix sparse).
  std::vector<int> row_index{0}, column_index{0};
  std::vector<double> values{0};
  for (int i = 0; i < columns; ++i)
    for (int j = 0; j < rows; ++j)
      if (const double value = double(p.rows(j, i)); value != 0)
        row_index.push_back(j + 1), column_index.push_back(i + 1), values.push_back(value);

  const GlpkEnvironment environment; // declared first: destroyed after the problem
  const QuietGlpk quiet;
  std::unique_ptr<glp_prob, DeleteProblem> owner(glp_create_prob());
  glp_prob* problem = owner.get();
  glp_add_rows(problem, rows);
  // Rows are the moments to within the rounding that b carries (else data on the boundary of the
  // grid's moment cone, like Diracs on grid points, come out infeasible by a rounding error that
  // T amplifies).
  for (int j = 0; j < rows; ++j) {
    const double centre = double(p.target[j]), width = double(options.rounding_band * p.band[j]);
    if (width > 0)
      glp_set_row_bnds(problem, j + 1, GLP_DB, centre - width, centre + width);
    else
      glp_set_row_bnds(problem, j + 1, GLP_FX, centre, centre);
  }
  glp_add_cols(problem, columns);
  for (int i = 0; i < columns; ++i) glp_set_col_bnds(problem, i + 1, GLP_LO, 0.0, 0.0);
  glp_load_matrix(problem, int(values.size()) - 1, row_index.data(), column_index.data(), values.data());

  // Harris' ratio test (GLPK's default) cycles on some problems (ESM's exp(20 z) on [-1.25, 1]:
  // 100000 iterations without progress) that the textbook test solves in 7, and the textbook test
  // stalls on others (power basis, wide grid) that Harris solves in a few hundred. The attempts run
  // in turn until one passes the long double check; the last one has GLPK's default tolerance.
  const Attempt attempts[] = {
      {options.presolve, options.glpk_scaling, options.tolerance, GLP_RT_HAR, "Harris ratio test"},
      {options.presolve, options.glpk_scaling, options.tolerance, GLP_RT_STD, "textbook ratio test"},
      {options.presolve, options.glpk_scaling, std::max(options.tolerance, 1e-7), GLP_RT_HAR, "tolerance 1e-7"}};
  const int iteration_limit = options.iteration_limit > 0 ? options.iteration_limit : 1000 + 2 * (rows + columns);
  LpBounds result;
  std::string solver;
  // Minimizes or maximizes the total weight of the grid points that `counts`.
  auto optimize = [&](bool minimize, auto counts, double& value, LpDistribution& argopt) {
    std::vector<Real> objective(columns);
    for (int i = 0; i < columns; ++i) {
      objective[i] = counts(grid[i]) ? p.scale[i] : 0; // sum of w_i = sum of d_i v_i
      glp_set_obj_coef(problem, i + 1, double(objective[i]));
    }
    glp_set_obj_dir(problem, minimize ? GLP_MIN : GLP_MAX);
    std::optional<Checked> best;
    std::vector<std::string> failures;
    for (std::size_t k = 0; k < std::size(attempts) && !best; ++k) {
      // The maximum starts from the minimum's optimal basis (feasible already): no presolve,
      // which would throw the basis away.
      Attempt attempt = attempts[k];
      const bool warm = !minimize && k == 0;
      attempt.presolve = attempt.presolve && !warm;
      std::string why = simplex(problem, attempt, warm, iteration_limit);
      if (why.empty() && options.exact) {
        glp_smcp parameters;
        glp_init_smcp(&parameters);
        parameters.msg_lev = GLP_MSG_OFF;
        const int code = glp_exact(problem, &parameters);
        const int status = glp_get_status(problem);
        why = code != 0              ? glpk_failure("glp_exact", code)
              : status == GLP_OPT    ? ""
              : status == GLP_NOFEAS ? "infeasible"
                                     : "glp_exact: not optimal";
      }
      if (why.empty()) {
        Checked c = check(problem, p, a, target, objective, minimize);
        if (c.acceptable(options.check_tolerance))
          best = std::move(c), solver = attempt.name;
        else
          why = "inaccurate (residual " + scientific(c.residual) + ", negative weight " + scientific(c.negative) +
                ", dual violation " + scientific(c.dual_violation) + ")";
      }
      if (!best) failures.push_back(std::string(attempt.name) + ": " + why);
    }
    if (!best) {
      // An attempt at the configured tolerance found no point within it: infeasible, whatever
      // the looser one's optimum (which failed the check) says.
      const bool infeasible = failures[0].ends_with(": infeasible") || failures[1].ends_with(": infeasible");
      std::string all;
      for (const std::string& failure : failures) all += (all.empty() ? "" : "; ") + failure;
      result.status = infeasible ? "infeasible" : all;
      return false;
    }
    Real sum = 0;
    for (int i = 0; i < columns; ++i) sum += counts(grid[i]) ? best->w[i] : 0;
    value = double(sum);
    argopt = distribution(best->w, grid);
    result.residual = std::max(result.residual, double(best->residual));
    result.dual_violation = std::max(result.dual_violation, double(best->dual_violation));
    result.solver = result.solver.empty() || result.solver == solver ? solver : result.solver + ", " + solver;
    return true;
  };
  if (!optimize(
          true, [zf](double z) { return z < zf; }, result.lower, result.lower_argmin))
    return result;
  if (!optimize(
          false, [zf](double z) { return z <= zf; }, result.upper, result.upper_argmax))
    return result;
  result.feasible = true;
  result.status = "optimal";
  return result;
}

} // namespace msm::oracle
