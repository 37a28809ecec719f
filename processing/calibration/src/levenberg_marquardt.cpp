#include "levenberg_marquardt.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace bsls::calibration::internal {

bool NumericJacobian(const ResidualFunction& f, const Eigen::VectorXd& x, double relative_step,
                     Eigen::MatrixXd* jacobian) {
  Eigen::VectorXd plus;
  Eigen::VectorXd minus;
  Eigen::VectorXd probe = x;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double h = relative_step * std::max(std::abs(x(j)), 1.0);
    probe(j) = x(j) + h;
    if (!f(probe, &plus)) return false;
    probe(j) = x(j) - h;
    if (!f(probe, &minus)) return false;
    probe(j) = x(j);
    if (j == 0) jacobian->resize(plus.size(), x.size());
    jacobian->col(j) = (plus - minus) / (2.0 * h);
  }
  return true;
}

std::optional<LmResult> MinimiseLeastSquares(const ResidualFunction& f, const Eigen::VectorXd& x0,
                                             const LmOptions& options) {
  LmResult result;
  result.x = x0;
  if (!f(result.x, &result.residuals)) return std::nullopt;
  if (!NumericJacobian(f, result.x, options.relative_step, &result.jacobian)) return std::nullopt;
  double cost = result.residuals.squaredNorm();
  result.initial_cost = cost;

  Eigen::MatrixXd normal = result.jacobian.transpose() * result.jacobian;
  Eigen::VectorXd gradient = result.jacobian.transpose() * result.residuals;
  // Marquardt scaling: damp each parameter in proportion to its own curvature,
  // so parameters of very different units (px, mm, radians) are treated alike.
  auto scaling = [](const Eigen::MatrixXd& a) {
    const double floor = 1e-12 * std::max(a.diagonal().maxCoeff(), 1e-300);
    return Eigen::VectorXd(a.diagonal().cwiseMax(floor));
  };
  Eigen::VectorXd diag = scaling(normal);
  double mu = 1e-3;
  double nu = 2.0;
  Eigen::VectorXd trial_residuals;
  for (int it = 0; it < options.max_iterations; ++it) {
    result.iterations = it + 1;
    if (gradient.lpNorm<Eigen::Infinity>() <= options.gradient_tolerance) {
      result.converged = true;
      break;
    }
    Eigen::MatrixXd damped = normal;
    damped.diagonal() += mu * diag;
    const Eigen::VectorXd step = damped.ldlt().solve(-gradient);
    if (!step.allFinite()) break;
    if (step.norm() <= options.step_tolerance * (result.x.norm() + options.step_tolerance)) {
      result.converged = true;
      break;
    }
    const Eigen::VectorXd trial = result.x + step;
    const bool valid = f(trial, &trial_residuals);
    const double trial_cost = valid ? trial_residuals.squaredNorm() : HUGE_VAL;
    // Cost of the linear model: |r + J dx|^2 = cost + 2 dx.g + dx.N dx.
    const double predicted = -(2.0 * step.dot(gradient) + step.dot(normal * step));
    const double rho = predicted > 0.0 ? (cost - trial_cost) / predicted : -1.0;
    if (valid && rho > 0.0) {
      const double reduction = cost - trial_cost;
      Eigen::MatrixXd trial_jacobian;
      if (!NumericJacobian(f, trial, options.relative_step, &trial_jacobian)) {
        // Accept the point but stop: the model's domain ends right beside it.
        result.x = trial;
        result.residuals = trial_residuals;
        cost = trial_cost;
        break;
      }
      result.x = trial;
      result.residuals = trial_residuals;
      result.jacobian = std::move(trial_jacobian);
      cost = trial_cost;
      normal = result.jacobian.transpose() * result.jacobian;
      gradient = result.jacobian.transpose() * result.residuals;
      diag = scaling(normal);
      mu *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      if (reduction <= options.cost_tolerance * cost) {
        result.converged = true;
        break;
      }
    } else {
      mu *= nu;
      nu *= 2.0;
      if (mu > 1e30) {
        // No step lowers the cost: we are at a minimum to machine precision.
        result.converged = true;
        break;
      }
    }
  }
  result.final_cost = cost;
  return result;
}

std::optional<Eigen::MatrixXd> CovarianceFromJacobian(const Eigen::MatrixXd& jacobian,
                                                      double sigma2) {
  const Eigen::VectorXd norms = jacobian.colwise().norm().transpose();
  if ((norms.array() <= 0.0).any() || !norms.allFinite()) return std::nullopt;
  const Eigen::MatrixXd scaled = jacobian * norms.cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  if (s.size() == 0 || s(s.size() - 1) <= 1e-12 * s(0)) return std::nullopt;
  const Eigen::MatrixXd& v = svd.matrixV();
  const Eigen::MatrixXd scaled_cov =
      v * s.array().square().inverse().matrix().asDiagonal() * v.transpose();
  return Eigen::MatrixXd(norms.cwiseInverse().asDiagonal() * scaled_cov *
                         norms.cwiseInverse().asDiagonal() * sigma2);
}

}  // namespace bsls::calibration::internal
