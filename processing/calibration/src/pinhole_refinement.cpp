#include "pinhole_refinement.h"

#include <Eigen/Geometry>
#include <cmath>

namespace bsls::calibration::internal {
namespace {

PinholeVector ToVector(const geometry::PinholeModel& model, FocalForm form) {
  const geometry::Intrinsics& in = model.intrinsics();
  PinholeVector v = PinholeVector::Zero();
  if (form == FocalForm::kFSx) {
    v(kFocalA) = in.fy;
    v(kFocalB) = in.fx / in.fy;
  } else {
    v(kFocalA) = in.fx;
    v(kFocalB) = in.fy;
  }
  v(kCx) = in.cx;
  v(kCy) = in.cy;
  v(kK1) = in.k1;
  v(kK2) = in.k2;
  v.segment<3>(kTx) = model.pose().translation;
  return v;  // w = 0: rotation is carried by the reference rotation
}

geometry::PinholeModel FromVector(const PinholeVector& v, FocalForm form,
                                  const Eigen::Matrix3d& reference_rotation) {
  geometry::Intrinsics in;
  if (form == FocalForm::kFSx) {
    in.fy = v(kFocalA);
    in.fx = v(kFocalA) * v(kFocalB);
  } else {
    in.fx = v(kFocalA);
    in.fy = v(kFocalB);
  }
  in.cx = v(kCx);
  in.cy = v(kCy);
  in.k1 = v(kK1);
  in.k2 = v(kK2);
  geometry::Pose pose;
  pose.rotation = RotationFromVector(v.segment<3>(kWx)) * reference_rotation;
  pose.translation = v.segment<3>(kTx);
  return geometry::PinholeModel(in, pose);
}

bool Residuals(const geometry::PinholeModel& model, const std::vector<Eigen::Vector3d>& world,
               const std::vector<Eigen::Vector2d>& image, Eigen::VectorXd* out) {
  out->resize(2 * static_cast<Eigen::Index>(world.size()));
  for (size_t i = 0; i < world.size(); ++i) {
    const auto projected = model.Project(world[i]);
    if (!projected) return false;
    out->segment<2>(2 * static_cast<Eigen::Index>(i)) = *projected - image[i];
  }
  return true;
}

}  // namespace

Eigen::Matrix3d RotationFromVector(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) {
    Eigen::Matrix3d skew;
    skew << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
    return Eigen::Matrix3d::Identity() + skew;
  }
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

std::optional<PinholeRefinement> RefinePinhole(const std::vector<Eigen::Vector3d>& world,
                                               const std::vector<Eigen::Vector2d>& image,
                                               const geometry::PinholeModel& initial,
                                               FocalForm form,
                                               const std::array<bool, kPinholeParamCount>& free,
                                               const LmOptions& options) {
  std::vector<int> index;
  for (int j = 0; j < kPinholeParamCount; ++j)
    if (free[static_cast<size_t>(j)]) index.push_back(j);

  // Packs the free parameters of `base` around a reference rotation.
  auto make_function = [&](const PinholeVector& base, const Eigen::Matrix3d& reference) {
    return [&, base, reference](const Eigen::VectorXd& x, Eigen::VectorXd* r) {
      PinholeVector full = base;
      for (size_t k = 0; k < index.size(); ++k) full(index[k]) = x(static_cast<Eigen::Index>(k));
      return Residuals(FromVector(full, form, reference), world, image, r);
    };
  };
  auto pack = [&](const PinholeVector& full) {
    Eigen::VectorXd x(static_cast<Eigen::Index>(index.size()));
    for (size_t k = 0; k < index.size(); ++k) x(static_cast<Eigen::Index>(k)) = full(index[k]);
    return x;
  };

  const PinholeVector start = ToVector(initial, form);
  const Eigen::Matrix3d start_rotation = initial.pose().rotation;
  const auto solved =
      MinimiseLeastSquares(make_function(start, start_rotation), pack(start), options);
  if (!solved) return std::nullopt;
  PinholeVector best = start;
  for (size_t k = 0; k < index.size(); ++k)
    best(index[k]) = solved->x(static_cast<Eigen::Index>(k));

  PinholeRefinement out;
  out.model = FromVector(best, form, start_rotation);
  out.iterations = solved->iterations;
  out.converged = solved->converged;
  out.residuals = solved->residuals;

  // Covariance at the optimum, re-linearised with w = 0 about the final rotation.
  const PinholeVector at_optimum = ToVector(out.model, form);
  const auto function = make_function(at_optimum, out.model.pose().rotation);
  Eigen::MatrixXd jacobian;
  const auto dof = static_cast<double>(out.residuals.size()) - static_cast<double>(index.size());
  out.residual_sigma = dof > 0.0 ? std::sqrt(out.residuals.squaredNorm() / dof) : 0.0;
  if (dof > 0.0 && NumericJacobian(function, pack(at_optimum), options.relative_step, &jacobian)) {
    if (const auto cov =
            CovarianceFromJacobian(jacobian, out.residual_sigma * out.residual_sigma)) {
      PinholeMatrix full = PinholeMatrix::Zero();
      for (size_t a = 0; a < index.size(); ++a)
        for (size_t b = 0; b < index.size(); ++b)
          full(index[a], index[b]) =
              (*cov)(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
      out.covariance = full;
    }
  }
  return out;
}

}  // namespace bsls::calibration::internal
