#include "bsls/calibration/projector_calibration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "bsls/pattern/brick_pattern.h"

namespace bsls::calibration {
namespace {

constexpr unsigned kSeed = 6021;
constexpr double kNoiseMm = 0.05;          // Gaussian, on x and y of the screen points
constexpr double kOutlierFraction = 0.02;  // gross outliers
// Gross outliers: displaced along x, or labelled two lines off (11 mm). The
// thesis's single rejection round drops points beyond 3 sigma of the first
// fit, whose sigma the outliers themselves inflate to ~1.5 mm: outliers must
// be well beyond 3 sigma of that. Smaller ones need more rounds (tested below).
constexpr double kOutlierMinMm = 8.0;
constexpr double kOutlierMaxMm = 14.0;
constexpr double kPlaneToleranceMm = 0.05;  // fitted vs true plane over the working volume
constexpr double kCentreToleranceMm = 2.0;
constexpr double kAxisToleranceRad = 2e-3;
constexpr double kSlideToleranceD = 0.01;  // 3x4 model reprojection, line pitches
constexpr double kExactMm = 1e-6;
constexpr double kCentralLineTolerance = 0.25;  // lines

const std::vector<double> kScreensMm = {0, 30, 60, 90, 120, 150};

// The simulator's projector (simulator/scene.h MakeProjector): slide units d,
// 128 d focal length, principal point (0, 0), 730 mm above the origin.
geometry::PinholeModel TrueProjector(const Eigen::Vector3d& centre = {0.0, 0.0, 730.0},
                                     const Eigen::Vector3d& target = Eigen::Vector3d::Zero(),
                                     double k1 = 0.0) {
  geometry::Intrinsics in;
  in.fx = in.fy = 128.0;
  in.cx = in.cy = 0.0;
  in.k1 = k1;
  in.k2 = 0.0;
  const auto pose = geometry::Pose::LookAt(centre, target, {0.0, 1.0, 0.0});
  EXPECT_TRUE(pose.has_value());
  return geometry::PinholeModel(in, *pose);
}

// Where the projector's ray through slide point st meets the screen z.
Eigen::Vector3d OnScreen(const geometry::PinholeModel& projector, const Eigen::Vector2d& st,
                         double z) {
  const geometry::Ray ray = projector.BackProject(st);
  return ray.At((z - ray.origin.z()) / ray.direction.z());
}

// The true light plane of line e (s = e): through the centre, containing the slide column.
LightPlane TruePlane(const geometry::PinholeModel& projector, double e) {
  const Eigen::Vector3d a = OnScreen(projector, {e, -20.0}, 0.0);
  const Eigen::Vector3d b = OnScreen(projector, {e, 20.0}, 0.0);
  const Eigen::Vector3d c = projector.Centre();
  Eigen::Vector3d n = (a - c).cross(b - c).normalized();
  if (n.x() < 0.0) n = -n;
  return {n, n.dot(c)};
}

struct Samples {
  std::vector<StripePoint> points;
  std::vector<bool> outlier;
};

// Points on the intersection of each light plane e = -10 .. 10 with each
// screen, as a camera would measure them: noise on x and y (z is the known
// screen position), and a fraction of gross outliers (displaced along x or
// given a wrong line label).
Samples SampleStripes(const std::function<Eigen::Vector3d(int e, double t, double z)>& point_of,
                      double noise_mm, double outlier_fraction,
                      double outlier_min_mm = kOutlierMinMm,
                      double outlier_max_mm = kOutlierMaxMm) {
  std::mt19937 rng(kSeed);
  std::normal_distribution<double> noise(0.0, noise_mm);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Samples out;
  for (double z : kScreensMm) {
    for (int e = -10; e <= 10; ++e) {
      for (double t = -20.0; t <= 20.0; t += 1.0) {
        StripePoint p{point_of(e, t, z), e};
        p.world_mm += Eigen::Vector3d(noise(rng), noise(rng), 0.0);
        bool outlier = false;
        if (unit(rng) < outlier_fraction) {
          outlier = true;
          const double sign = unit(rng) < 0.5 ? -1.0 : 1.0;
          if (unit(rng) < 0.5) {
            p.world_mm.x() +=
                sign * (outlier_min_mm + (outlier_max_mm - outlier_min_mm) * unit(rng));
          } else {
            p.line += static_cast<int>(sign) * 2;
          }
        }
        out.points.push_back(p);
        out.outlier.push_back(outlier);
      }
    }
  }
  return out;
}

Samples SampleProjector(const geometry::PinholeModel& projector, double noise_mm,
                        double outlier_fraction, double outlier_min_mm = kOutlierMinMm,
                        double outlier_max_mm = kOutlierMaxMm) {
  return SampleStripes(
      [&](int e, double t, double z) {
        return OnScreen(projector, {e, t}, z);
      },
      noise_mm, outlier_fraction, outlier_min_mm, outlier_max_mm);
}

// Largest distance from the fitted plane of true plane points in the volume
// (screens z = 0 .. 150 mm, slide rows -20 .. 20).
double PlaneDeviation(const geometry::PinholeModel& projector, double e, const LightPlane& fitted) {
  double worst = 0.0;
  for (double z = 0.0; z <= 150.0; z += 25.0)
    for (double t = -20.0; t <= 20.0; t += 5.0)
      worst = std::max(worst, std::abs(fitted.SignedDistance(OnScreen(projector, {e, t}, z))));
  return worst;
}

void ExpectOutliersRejected(const Samples& samples, const StripeFitReport& report) {
  ASSERT_EQ(report.inlier.size(), samples.points.size());
  int outliers = 0;
  int inliers_dropped = 0;
  for (size_t i = 0; i < samples.points.size(); ++i) {
    if (samples.outlier[i]) {
      ++outliers;
      EXPECT_FALSE(report.inlier[i]) << "outlier " << i << " kept";
    } else if (!report.inlier[i]) {
      ++inliers_dropped;
    }
  }
  EXPECT_GT(outliers, 0);
  EXPECT_LT(inliers_dropped, static_cast<int>(0.005 * samples.points.size()) + 1);
  EXPECT_EQ(report.points_dropped, outliers + inliers_dropped);
}

TEST(ParallelPlaneModel, RecoversParallelPlanesAndRejectsOutliers) {
  // Thesis 6.2.1: planes n.r = d0 (e - e0) with a common normal.
  const Eigen::Vector3d normal = Eigen::Vector3d(0.97, 0.05, 0.22).normalized();
  const double d0 = 5.7;
  const double e0 = 0.4;
  const Eigen::Vector3d in_plane_a = normal.cross(Eigen::Vector3d::UnitZ()).normalized();
  auto point_of = [&](int e, double t, double z) {
    // The point of plane e at height z and "row" t along the plane's horizontal-ish direction.
    const Eigen::Vector3d base = normal * (d0 * (e - e0));
    Eigen::Vector3d p = base + 5.0 * t * in_plane_a;
    // Move within the plane to the screen z.
    const Eigen::Vector3d up = normal.cross(in_plane_a).normalized();
    p += up * ((z - p.z()) / up.z());
    return p;
  };
  const Samples samples = SampleStripes(point_of, kNoiseMm, kOutlierFraction);
  const ParallelPlaneFit fit = FitParallelPlaneModel(samples.points);
  EXPECT_LT(std::acos(std::min(1.0, fit.model.normal.dot(normal))), 1e-3);
  EXPECT_NEAR(fit.model.spacing_mm, d0, 2e-3);
  EXPECT_NEAR(fit.model.e0, e0, 2e-3);
  ExpectOutliersRejected(samples, fit.report);
  EXPECT_LT(fit.report.rms_mm, 1.2 * kNoiseMm);
  EXPECT_GT(fit.report.first_pass_rms_mm, 5.0 * fit.report.rms_mm);
  for (int e = -10; e <= 10; e += 5) {
    const LightPlane plane = fit.model.PlaneOfLine(e);
    EXPECT_LT(std::abs(plane.SignedDistance(point_of(e, 0.0, 75.0))), kPlaneToleranceMm) << e;
  }
}

TEST(PerspectivePlaneModel, RecoversTheRigProjectorAndRejectsOutliers) {
  const geometry::PinholeModel truth = TrueProjector();
  const Samples samples = SampleProjector(truth, kNoiseMm, kOutlierFraction);
  const PerspectivePlaneFit fit = FitPerspectivePlaneModel(samples.points);
  ExpectOutliersRejected(samples, fit.report);
  EXPECT_LT(fit.report.rms_mm, 1.2 * kNoiseMm);
  for (int e = -10; e <= 10; ++e) {
    EXPECT_LT(PlaneDeviation(truth, e, fit.model.PlaneOfLine(e)), kPlaneToleranceMm) << e;
  }
  // Vertical lines: normals along x (gauge n_x = 1), pencil axis along y
  // (P0 fixed at y = 0), which for this projector is its true centre.
  EXPECT_EQ(fit.model.gauge_axis, 0);
  EXPECT_EQ(fit.model.centre_axis, 1);
  EXPECT_LT((fit.model.centre_mm - truth.Centre()).norm(), kCentreToleranceMm);
  EXPECT_NEAR(fit.centre_to_origin_mm, 730.0, kCentreToleranceMm);
  const Eigen::Vector3d true_axis = truth.pose().rotation.row(1).transpose();
  EXPECT_LT(std::acos(std::min(1.0, std::abs(fit.model.axis_direction.dot(true_axis)))),
            kAxisToleranceRad);
  // Line 0 is the central line of this projector (principal point at s = 0);
  // p.n0 is the least determined part of the fit (about 0.06 lines sd here).
  EXPECT_NEAR(fit.model.CentralLine(), 0.0, kCentralLineTolerance);
  std::cout << "[ perspective ] P0 " << fit.model.centre_mm.transpose() << " mm, |P0| "
            << fit.centre_to_origin_mm << " mm, rms " << fit.report.rms_mm << " mm (first pass "
            << fit.report.first_pass_rms_mm << "), max " << fit.report.max_mm << " mm, dropped "
            << fit.report.points_dropped << " of " << samples.points.size() << "\n";
}

TEST(PerspectivePlaneModel, CentreLiesOnTheTrueAxisOfATiltedProjector) {
  const geometry::PinholeModel truth = TrueProjector({40.0, 25.0, 700.0}, {-10.0, 0.0, 0.0});
  const Samples samples = SampleProjector(truth, kNoiseMm, kOutlierFraction);
  const PerspectivePlaneFit fit = FitPerspectivePlaneModel(samples.points);
  ExpectOutliersRejected(samples, fit.report);
  const Eigen::Vector3d axis = truth.pose().rotation.row(1).transpose();
  const Eigen::Vector3d off = fit.model.centre_mm - truth.Centre();
  // On the true pencil axis (the line through the centre along the slide
  // columns), at its point with y = 0: the stripes cannot say more.
  EXPECT_LT((off - off.dot(axis) * axis).norm(), kCentreToleranceMm);
  EXPECT_NEAR(fit.model.centre_mm.y(), 0.0, 1e-9);
  const Eigen::Vector3d expected = truth.Centre() - axis * (truth.Centre().y() / axis.y());
  EXPECT_LT((fit.model.centre_mm - expected).norm(), kCentreToleranceMm);
  for (int e = -10; e <= 10; ++e)
    EXPECT_LT(PlaneDeviation(truth, e, fit.model.PlaneOfLine(e)), kPlaneToleranceMm) << e;
}

TEST(PerspectivePlaneModel, MoreRoundsRejectSmallerOutliers) {
  // Outliers from 1.5 mm (30 sigma of the noise) to 14 mm: one round keeps the
  // small ones (3 sigma of the first fit is ~4 mm); three rounds drop them all.
  const geometry::PinholeModel truth = TrueProjector();
  const Samples samples = SampleProjector(truth, kNoiseMm, kOutlierFraction, 1.5, 14.0);
  const PerspectivePlaneFit thesis = FitPerspectivePlaneModel(samples.points);
  StripeFitParams params;
  params.rejection_rounds = 3;
  const PerspectivePlaneFit more = FitPerspectivePlaneModel(samples.points, params);
  ExpectOutliersRejected(samples, more.report);
  EXPECT_LT(more.report.rms_mm, 1.2 * kNoiseMm);
  EXPECT_GT(thesis.report.rms_mm, more.report.rms_mm);
  std::cout << "[ rounds ] 1 round: rms " << thesis.report.rms_mm << " mm, dropped "
            << thesis.report.points_dropped << "; 3 rounds: rms " << more.report.rms_mm
            << " mm, dropped " << more.report.points_dropped << "\n";
}

TEST(PerspectivePlaneModel, ExactWithoutNoise) {
  const geometry::PinholeModel truth = TrueProjector({40.0, 25.0, 700.0}, {-10.0, 0.0, 0.0});
  const Samples samples = SampleProjector(truth, 0.0, 0.0);
  const PerspectivePlaneFit fit = FitPerspectivePlaneModel(samples.points);
  EXPECT_EQ(fit.report.points_dropped, 0);
  EXPECT_LT(fit.report.max_mm, kExactMm);
  for (int e = -10; e <= 10; e += 4) {
    const LightPlane expected = TruePlane(truth, e);
    const LightPlane got = fit.model.PlaneOfLine(e);
    const double sign = got.normal.dot(expected.normal) < 0.0 ? -1.0 : 1.0;
    EXPECT_LT((sign * got.normal - expected.normal).norm(), 1e-9) << e;
    EXPECT_NEAR(sign * got.offset_mm, expected.offset_mm, kExactMm) << e;
  }
}

TEST(PerspectivePlaneModel, BeatsTheParallelModelOnAPerspectiveProjector) {
  const geometry::PinholeModel truth = TrueProjector();
  const Samples samples = SampleProjector(truth, kNoiseMm, 0.0);
  StripeFitParams no_rejection;
  no_rejection.outlier_sigma = 0.0;
  const ParallelPlaneFit parallel = FitParallelPlaneModel(samples.points, no_rejection);
  const PerspectivePlaneFit perspective = FitPerspectivePlaneModel(samples.points, no_rejection);
  std::cout << "[ models ] parallel rms " << parallel.report.rms_mm << " mm (max "
            << parallel.report.max_mm << "), perspective rms " << perspective.report.rms_mm
            << " mm (max " << perspective.report.max_mm << ")\n";
  EXPECT_GT(parallel.report.rms_mm, 5.0 * perspective.report.rms_mm);
  EXPECT_LT(perspective.report.rms_mm, 1.2 * kNoiseMm);
}

std::vector<JunctionPoint> SampleJunctions(const geometry::PinholeModel& projector,
                                           pattern::Side side, double noise_mm,
                                           double outlier_fraction, std::vector<bool>* outlier,
                                           std::vector<JunctionPoint>* exact = nullptr) {
  std::mt19937 rng(kSeed + 1);
  std::normal_distribution<double> noise(0.0, noise_mm);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const pattern::PatternSpec spec;
  std::vector<JunctionPoint> out;
  for (double z : kScreensMm) {
    for (const pattern::SlideJunction& j : pattern::AllJunctions(spec)) {
      if (std::abs(j.v) > 20) continue;  // the part of the slide the screen catches
      const Eigen::Vector2d st = SlideOfJunction(side, j.p, j.v);
      const JunctionPoint truth{OnScreen(projector, st, z), st};
      if (exact) exact->push_back(truth);
      JunctionPoint p = truth;
      p.world_mm += Eigen::Vector3d(noise(rng), noise(rng), 0.0);
      const bool bad = unit(rng) < outlier_fraction;
      if (bad) {
        p.world_mm.x() += (unit(rng) < 0.5 ? -1.0 : 1.0) *
                          (kOutlierMinMm + (kOutlierMaxMm - kOutlierMinMm) * unit(rng));
      }
      outlier->push_back(bad);
      out.push_back(p);
    }
  }
  return out;
}

TEST(ProjectorMatrix, FromJunctionsReprojectsWithinAHundredthOfAPitch) {
  const geometry::PinholeModel truth = TrueProjector({20.0, -15.0, 730.0});
  std::vector<bool> outlier;
  std::vector<JunctionPoint> exact;
  const auto junctions =
      SampleJunctions(truth, pattern::Side::kLeft, kNoiseMm, kOutlierFraction, &outlier, &exact);
  const ProjectorMatrixFit fit = FitProjectorMatrix(junctions);
  int outliers = 0;
  for (size_t i = 0; i < junctions.size(); ++i) {
    if (!outlier[i]) continue;
    ++outliers;
    EXPECT_FALSE(fit.report.inlier[i]) << "outlier " << i << " kept";
  }
  EXPECT_GT(outliers, 0);
  EXPECT_LE(fit.report.points_dropped, outliers + static_cast<int>(0.005 * junctions.size()) + 1);
  // The model and its 3x4 matrix against the true (noise-free) junctions.
  double worst_model = 0.0;
  double worst_matrix = 0.0;
  for (const JunctionPoint& j : exact) {
    const auto st = fit.model.Project(j.world_mm);
    ASSERT_TRUE(st.has_value());
    worst_model = std::max(worst_model, (*st - j.slide_st).norm());
    const Eigen::Vector3d h = fit.matrix * j.world_mm.homogeneous();
    worst_matrix = std::max(worst_matrix, (h.hnormalized() - j.slide_st).norm());
  }
  EXPECT_LT(worst_model, kSlideToleranceD);
  EXPECT_LT(worst_matrix, kSlideToleranceD);
  EXPECT_LT((fit.model.Centre() - truth.Centre()).norm(), kCentreToleranceMm);
  EXPECT_NEAR(fit.model.intrinsics().fx, 128.0, 0.5);
  std::cout << "[ matrix ] worst true-junction reprojection " << worst_model << " d (matrix "
            << worst_matrix << " d), fit rms " << fit.report.rms_d << " d, centre off "
            << (fit.model.Centre() - truth.Centre()).norm() << " mm, dropped "
            << fit.report.points_dropped << " of " << junctions.size() << " (" << outliers
            << " outliers)\n";

  // Its light planes agree with the true ones (line p of the left slide: s = -p).
  for (int p = 0; p < 20; p += 3) {
    const double s = pattern::SFromU(pattern::Side::kLeft, p);
    EXPECT_LT(PlaneDeviation(truth, s, LightPlaneOfSlideColumn(fit.model, s)), kPlaneToleranceMm)
        << p;
  }
}

TEST(ProjectorMatrix, LightPlaneOfSlideColumnIsExactForTheTrueModel) {
  const geometry::PinholeModel truth = TrueProjector({20.0, -15.0, 730.0});
  for (int s = -10; s <= 10; s += 5) {
    const LightPlane expected = TruePlane(truth, s);
    const LightPlane got = LightPlaneOfSlideColumn(truth, s);
    EXPECT_LT((got.normal - expected.normal).norm(), 1e-12) << s;
    EXPECT_NEAR(got.offset_mm, expected.offset_mm, 1e-9) << s;
    // Ray/plane triangulation through the plane gives back the screen point.
    const Eigen::Vector3d on_screen = OnScreen(truth, {s, 7.0}, 40.0);
    const geometry::Ray camera_ray{{-240.0, 0.0, 340.0},
                                   (on_screen - Eigen::Vector3d(-240.0, 0.0, 340.0)).normalized()};
    const auto hit = got.Intersect(camera_ray);
    ASSERT_TRUE(hit.has_value());
    EXPECT_LT((*hit - on_screen).norm(), 1e-9);
  }
  EXPECT_THROW(LightPlaneOfSlideColumn(truth, 0.0, 0.0), CalibrationError);
}

CalibrationErrorReason PerspectiveReason(const std::vector<StripePoint>& points,
                                         const StripeFitParams& params = {}) {
  try {
    FitPerspectivePlaneModel(points, params);
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("perspective projector model"), std::string::npos);
    return e.reason();
  }
  ADD_FAILURE() << "no CalibrationError";
  return CalibrationErrorReason::kInvalidInput;
}

TEST(ProjectorCalibration, RejectsDegenerateInput) {
  const geometry::PinholeModel truth = TrueProjector();
  const Samples samples = SampleProjector(truth, kNoiseMm, 0.0);

  // One screen only: coplanar.
  std::vector<StripePoint> one_screen;
  for (const auto& p : samples.points)
    if (p.world_mm.z() == 0.0) one_screen.push_back(p);
  EXPECT_EQ(PerspectiveReason(one_screen), CalibrationErrorReason::kCoplanar);
  EXPECT_THROW(FitParallelPlaneModel(one_screen), CalibrationError);

  // One line only, or two: too few lines for the pencil.
  std::vector<StripePoint> two_lines;
  for (const auto& p : samples.points)
    if (p.line == 0 || p.line == 3) two_lines.push_back(p);
  EXPECT_EQ(PerspectiveReason(two_lines), CalibrationErrorReason::kTooFewPoints);
  std::vector<StripePoint> one_line;
  for (const auto& p : samples.points)
    if (p.line == 0) one_line.push_back(p);
  try {
    FitParallelPlaneModel(one_line);
    FAIL() << "one line accepted";
  } catch (const CalibrationError& e) {
    EXPECT_EQ(e.reason(), CalibrationErrorReason::kTooFewPoints);
  }
  EXPECT_EQ(PerspectiveReason({}), CalibrationErrorReason::kTooFewPoints);

  // Exactly parallel planes: no finite centre.
  const Samples parallel = SampleStripes(
      [](int e, double t, double z) { return Eigen::Vector3d(5.7 * e, 5.0 * t, z); }, 0.0, 0.0);
  EXPECT_EQ(PerspectiveReason(parallel.points), CalibrationErrorReason::kDegenerate);

  // Bad input and params.
  std::vector<StripePoint> bad = samples.points;
  bad[10].world_mm.y() = NAN;
  EXPECT_EQ(PerspectiveReason(bad), CalibrationErrorReason::kInvalidInput);
  StripeFitParams params;
  params.outlier_sigma = 0.5;
  EXPECT_EQ(PerspectiveReason(samples.points, params), CalibrationErrorReason::kInvalidParams);

  std::vector<JunctionPoint> few(5);
  EXPECT_THROW(FitProjectorMatrix(few), CalibrationError);
  std::vector<bool> outlier;
  auto coplanar = SampleJunctions(truth, pattern::Side::kRight, 0.0, 0.0, &outlier);
  coplanar.resize(100);  // all on the first screen
  try {
    FitProjectorMatrix(coplanar);
    FAIL() << "coplanar junctions accepted";
  } catch (const CalibrationError& e) {
    EXPECT_EQ(e.reason(), CalibrationErrorReason::kCoplanar) << e.what();
    EXPECT_NE(std::string(e.what()).find("projector matrix"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bsls::calibration
