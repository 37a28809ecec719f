// Holes of a measured surface filled by interpolation, for the lesion
// measurement (lesion_measure.cpp): a scalar field (the deviation from the
// reference) sampled on a square x-y grid where the surface covers a cell's
// centre, and interpolated over each hole the covered cells enclose.
//
// Two interpolants: a membrane (harmonic: the discrete Laplacian is zero in
// the hole; no extremum inside it, so it flattens a bump's top) and a thin
// plate (the squared discrete Laplacian summed over the hole and its rim is
// least: the field's slope carries across the rim, so a smooth bump's flank
// continues into the hole). Their difference says how far the guess can be
// trusted.
#ifndef BSLS_MEASUREMENT_SRC_HOLE_FILL_H_
#define BSLS_MEASUREMENT_SRC_HOLE_FILL_H_

#include <Eigen/Core>
#include <vector>

#include "bsls/measurement/surface_query.h"

namespace bsls::measurement::internal {

// A scalar field on cols x rows square cells; cell (c, r) is centred at
// origin + cell_mm * (c + 0.5, r + 0.5). Unknown cells hold NaN.
struct GridField {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // mm
  double cell_mm = 0.5;
  int cols = 0, rows = 0;
  std::vector<double> value;  // row-major, cols * rows

  // The centre of cell `index`, mm.
  Eigen::Vector2d Centre(int index) const;
};

// 1 for every cell of `field`'s grid whose centre lies inside `polygon`
// (even-odd rule, as internal::Contains), by scanlines: O(rows x corners).
std::vector<char> InsideMask(const GridField& field, const Polygon2d& polygon);

// The unknown cells of `field` that form holes: 4-connected sets of unknown
// cells that touch no border of the grid (the known cells enclose them),
// each with a label >= 0 (-1: known, or unknown but open to the border).
std::vector<int> EnclosedHoles(const GridField& field);

// `field`'s values with the cells of every enclosed hole (EnclosedHoles)
// interpolated from the known cells around it, both ways; open unknown cells
// stay NaN.
struct FilledField {
  std::vector<double> thin_plate;
  std::vector<double> membrane;
};
FilledField FillHoles(const GridField& field);

}  // namespace bsls::measurement::internal

#endif  // BSLS_MEASUREMENT_SRC_HOLE_FILL_H_
