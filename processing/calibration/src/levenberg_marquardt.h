// A small dense Levenberg-Marquardt least-squares minimiser with a numeric
// (central-difference) Jacobian, for the few-parameter refinements of
// calibration (thesis 6.1, Tsai's non-linear stage). Internal to
// bsls_calibration.
//
// Chosen over Eigen's unsupported LevenbergMarquardt so that the damping,
// the stopping rules and the final Jacobian (for parameter covariances) are
// ours to see and test; problems here have at most a dozen parameters and a
// few thousand residuals, so a dense J^T J solve per step is cheap.
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_CALIBRATION_SRC_LEVENBERG_MARQUARDT_H_
#define BSLS_CALIBRATION_SRC_LEVENBERG_MARQUARDT_H_

#include <Eigen/Core>
#include <functional>
#include <optional>

namespace bsls::calibration::internal {

// Fills *residuals for parameters x; returns false when x is outside the
// model's domain (e.g. a point behind the camera): such a step is refused.
using ResidualFunction = std::function<bool(const Eigen::VectorXd& x, Eigen::VectorXd* residuals)>;

struct LmOptions {
  int max_iterations = 200;
  double gradient_tolerance = 1e-12;  // stop when |J^T r|_inf falls below (cost units)
  double step_tolerance = 1e-12;      // stop when |dx| <= tol * (|x| + tol)
  double cost_tolerance = 1e-14;      // stop when an accepted step lowers cost by < tol * cost
  double relative_step = 1e-6;        // numeric-derivative step: h = relative_step * max(|x|, 1)
};

struct LmResult {
  Eigen::VectorXd x;
  Eigen::VectorXd residuals;  // at x
  Eigen::MatrixXd jacobian;   // at x, rows = residuals, columns = parameters
  double initial_cost = 0.0;  // sum of squared residuals at the start
  double final_cost = 0.0;
  int iterations = 0;
  bool converged = false;  // a tolerance was met (not the iteration limit)
};

// Minimises |f(x)|^2 from x0 (Marquardt scaling, Nielsen's damping update).
// nullopt when f refuses x0 or its neighbourhood (no Jacobian can be formed).
std::optional<LmResult> MinimiseLeastSquares(const ResidualFunction& f, const Eigen::VectorXd& x0,
                                             const LmOptions& options);

// Central-difference Jacobian of f at x; false when f refuses a probe point.
bool NumericJacobian(const ResidualFunction& f, const Eigen::VectorXd& x, double relative_step,
                     Eigen::MatrixXd* jacobian);

// Covariance (J^T J)^-1 * sigma2 with column equilibration; nullopt when J is
// rank deficient (relative singular value below 1e-12): a parameter is then
// not determined by the data.
std::optional<Eigen::MatrixXd> CovarianceFromJacobian(const Eigen::MatrixXd& jacobian,
                                                      double sigma2);

}  // namespace bsls::calibration::internal

#endif  // BSLS_CALIBRATION_SRC_LEVENBERG_MARQUARDT_H_
