#include "bsls/reconstruction/island_placement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include "bsls/reconstruction/calibrated_model.h"

namespace bsls::reconstruction {

namespace {

// The median of `values` (reordered); NaN when empty.
double MedianOf(std::vector<double>* values) {
  if (values->empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = values->begin() + static_cast<std::ptrdiff_t>(values->size() / 2);
  std::nth_element(values->begin(), mid, values->end());
  return *mid;
}

// How one candidate shift fits: the whole row of the island's frame it
// moves to, and the RMS of the rows about it.
struct Fit {
  int dv = 0;        // island row + dv = slide row
  double rms = NAN;  // rows, the worst tenth left out; NaN: ruled out
};

class EpipolarGeometry final : public decoder::LabelGeometry {
 public:
  EpipolarGeometry(const calibration::SideCalibration& calibration,
                   const IslandPlacementParams& params)
      : calibration_(calibration), lines_(calibration.pattern.lines), params_(params) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& v : calibration.camera_views)
      lo = std::min(lo, v.z_mm), hi = std::max(hi, v.z_mm);
    for (const auto& v : calibration.screen_views)
      lo = std::min(lo, v.z_mm), hi = std::max(hi, v.z_mm);
    if (!(lo <= hi)) lo = hi = 0.0;  // a file without view reports: the base plane only
    z_min_ = lo - params.volume_margin_mm;
    z_max_ = hi + params.volume_margin_mm;
  }

  std::optional<decoder::LabelShift> PlaceIsland(
      const std::vector<decoder::FramedJunction>& labelled,
      const std::vector<decoder::FramedJunction>& island, std::string* why) const override;
  std::vector<char> RuleOut(const std::vector<decoder::FramedJunction>& labelled) const override;

 private:
  // The slide row of the junction on camera ray `ray` on the light plane of
  // line p, and whether that point lies in the measuring volume; nullopt where the
  // ray misses the plane or the projector.
  std::optional<std::pair<double, bool>> SlideRow(const geometry::Ray& ray, int p) const;
  // The camera rays through the junctions of `island`, in its order.
  std::vector<geometry::Ray> Rays(const std::vector<decoder::FramedJunction>& island) const;
  // Whether the junction on camera ray `ray`, labelled (p, q), misses its slide row
  // under `offset` (slide row = q + offset) by more than max_junction_rows,
  // or cannot be placed on the slide.
  bool OffItsRow(const geometry::Ray& ray, int p, int q, int offset) const;
  // The rows of line 0's component: the even offset from its q to slide rows.
  std::optional<int> RowOffset(const std::vector<decoder::FramedJunction>& labelled,
                               const std::vector<geometry::Ray>& rays, std::string* why) const;
  // The fit of `island` (with its camera rays) shifted by dp.
  Fit FitShift(const std::vector<decoder::FramedJunction>& island,
               const std::vector<geometry::Ray>& rays, int dp) const;

  calibration::SideCalibration calibration_;
  int lines_;
  IslandPlacementParams params_;
  double z_min_ = 0.0, z_max_ = 0.0;
};

std::optional<std::pair<double, bool>> EpipolarGeometry::SlideRow(const geometry::Ray& ray,
                                                                  int p) const {
  const auto on = JunctionOnSlide(calibration_, ray, p);
  if (!on) return std::nullopt;
  return std::make_pair(on->slide.y(), on->world.z() >= z_min_ && on->world.z() <= z_max_);
}

std::vector<geometry::Ray> EpipolarGeometry::Rays(
    const std::vector<decoder::FramedJunction>& island) const {
  std::vector<geometry::Ray> rays;
  rays.reserve(island.size());
  for (const decoder::FramedJunction& j : island)
    rays.push_back(calibration_.camera.model.BackProject({j.position.x, j.position.y}));
  return rays;
}

bool EpipolarGeometry::OffItsRow(const geometry::Ray& ray, int p, int q, int offset) const {
  const auto row = SlideRow(ray, p);
  return !row || std::abs(row->first - q - offset) > params_.max_junction_rows;
}

// As SlideRowOffset (calibrated_model.h), on the junctions the decoder has.
std::optional<int> EpipolarGeometry::RowOffset(const std::vector<decoder::FramedJunction>& labelled,
                                               const std::vector<geometry::Ray>& rays,
                                               std::string* why) const {
  std::vector<double> residue;
  for (size_t k = 0; k < labelled.size(); ++k)
    if (const auto row = SlideRow(rays[k], labelled[k].p))
      residue.push_back(row->first - labelled[k].q);
  if (static_cast<int>(residue.size()) < params_.min_junctions) {
    if (why)
      *why = "line 0's part has " + std::to_string(residue.size()) + " junctions on the slide";
    return std::nullopt;
  }
  return EvenRowOffset(&residue);
}

Fit EpipolarGeometry::FitShift(const std::vector<decoder::FramedJunction>& island,
                               const std::vector<geometry::Ray>& rays, int dp) const {
  Fit fit;
  std::vector<double> rows;
  rows.reserve(island.size());
  int inside = 0;
  for (size_t k = 0; k < island.size(); ++k) {
    const decoder::FramedJunction& j = island[k];
    const auto row = SlideRow(rays[k], j.p + dp);
    if (!row) continue;
    rows.push_back(row->first - j.q);
    inside += row->second;
  }
  if (rows.empty() || inside < params_.min_inside * static_cast<double>(island.size())) return fit;
  std::vector<double> sorted = rows;
  const double median = MedianOf(&sorted);
  // The nearest whole row keeping p + q's parity: dp + dv even.
  const int parity = ((dp % 2) + 2) % 2;
  fit.dv = 2 * static_cast<int>(std::lround((median - parity) / 2.0)) + parity;
  std::vector<double> miss;
  miss.reserve(rows.size());
  for (double r : rows) miss.push_back((r - fit.dv) * (r - fit.dv));
  std::sort(miss.begin(), miss.end());
  miss.resize(std::max<size_t>(1, miss.size() - miss.size() / 10));
  double sum = 0.0;
  for (double m : miss) sum += m;
  fit.rms = std::sqrt(sum / static_cast<double>(miss.size()));
  return fit;
}

std::optional<decoder::LabelShift> EpipolarGeometry::PlaceIsland(
    const std::vector<decoder::FramedJunction>& labelled,
    const std::vector<decoder::FramedJunction>& island, std::string* why) const {
  auto fail = [why](const std::string& reason) {
    if (why) *why = reason;
    return std::nullopt;
  };
  if (static_cast<int>(island.size()) < params_.min_junctions)
    return fail("the island has " + std::to_string(island.size()) + " junctions");
  // Judging line 0's component (island == labelled), its rays serve both.
  const std::vector<geometry::Ray> rays = Rays(island);
  const bool same = &labelled == &island;
  const std::vector<geometry::Ray> others = same ? std::vector<geometry::Ray>() : Rays(labelled);
  const auto offset = RowOffset(labelled, same ? rays : others, why);
  if (!offset) return std::nullopt;
  int lo = std::numeric_limits<int>::max(), hi = std::numeric_limits<int>::min();
  for (const decoder::FramedJunction& j : island) lo = std::min(lo, j.p), hi = std::max(hi, j.p);
  // Every shift that keeps the island's lines on the slide.
  std::optional<int> best;
  Fit best_fit;
  double rival = std::numeric_limits<double>::infinity();
  for (int dp = -lo; hi + dp < lines_; ++dp) {
    const Fit fit = FitShift(island, rays, dp);
    if (std::isnan(fit.rms)) continue;
    if (!best || fit.rms < best_fit.rms) {
      if (best) rival = std::min(rival, best_fit.rms);
      best = dp;
      best_fit = fit;
    } else {
      rival = std::min(rival, fit.rms);
    }
  }
  if (!best) return fail("no shift keeps the island inside the measuring volume");
  if (best_fit.rms > params_.max_rms_rows)
    return fail("the best shift misses whole rows by " + std::to_string(best_fit.rms) +
                " rows RMS");
  if (rival < std::max(params_.min_rival_ratio * best_fit.rms, params_.min_rival_rms_rows))
    return fail("two shifts fit (" + std::to_string(best_fit.rms) + " and " +
                std::to_string(rival) + " rows RMS)");
  decoder::LabelShift shift{*best, best_fit.dv - *offset, {}};
  shift.ruled_out.reserve(island.size());
  for (size_t k = 0; k < island.size(); ++k)
    shift.ruled_out.push_back(OffItsRow(rays[k], island[k].p + *best, island[k].q, best_fit.dv));
  return shift;
}

std::vector<char> EpipolarGeometry::RuleOut(
    const std::vector<decoder::FramedJunction>& labelled) const {
  std::vector<char> out(labelled.size(), 0);
  const std::vector<geometry::Ray> rays = Rays(labelled);
  const auto offset = RowOffset(labelled, rays, nullptr);
  if (!offset) return out;
  for (size_t k = 0; k < labelled.size(); ++k)
    out[k] = OffItsRow(rays[k], labelled[k].p, labelled[k].q, *offset);
  return out;
}

}  // namespace

bool IslandPlacementParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(volume_margin_mm >= 0)) return fail("IslandPlacementParams.volume_margin_mm must be >= 0");
  if (!(min_inside > 0 && min_inside <= 1))
    return fail("IslandPlacementParams.min_inside must lie in (0, 1]");
  if (min_junctions < 3) return fail("IslandPlacementParams.min_junctions must be >= 3");
  if (!(max_rms_rows > 0)) return fail("IslandPlacementParams.max_rms_rows must be positive");
  if (!(min_rival_ratio >= 1)) return fail("IslandPlacementParams.min_rival_ratio must be >= 1");
  if (!(min_rival_rms_rows > 0))
    return fail("IslandPlacementParams.min_rival_rms_rows must be positive");
  if (!(max_junction_rows > 0))
    return fail("IslandPlacementParams.max_junction_rows must be positive");
  return true;
}

std::shared_ptr<const decoder::LabelGeometry> LabelGeometryOfCalibration(
    const calibration::SideCalibration& calibration, const IslandPlacementParams& params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument("LabelGeometryOfCalibration: " + error);
  if (!calibration.projector_matrix) return nullptr;
  return std::make_shared<EpipolarGeometry>(calibration, params);
}

}  // namespace bsls::reconstruction
