#include "hole_fill.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

namespace bsls::measurement::internal {
namespace {

constexpr int kOpen = -1;

bool Known(const GridField& field, int index) { return !std::isnan(field.value[index]); }

// The 4-neighbours of cell `index` (fewer at the border).
std::vector<int> Neighbours(const GridField& field, int index) {
  const int c = index % field.cols, r = index / field.cols;
  std::vector<int> out;
  if (c > 0) out.push_back(index - 1);
  if (c + 1 < field.cols) out.push_back(index + 1);
  if (r > 0) out.push_back(index - field.cols);
  if (r + 1 < field.rows) out.push_back(index + field.cols);
  return out;
}

bool OnBorder(const GridField& field, int index) {
  const int c = index % field.cols, r = index / field.cols;
  return c == 0 || r == 0 || c + 1 == field.cols || r + 1 == field.rows;
}

}  // namespace

Eigen::Vector2d GridField::Centre(int index) const {
  return origin + cell_mm * Eigen::Vector2d(index % cols + 0.5, index / cols + 0.5);
}

std::vector<char> InsideMask(const GridField& field, const Polygon2d& polygon) {
  std::vector<char> inside(static_cast<std::size_t>(field.cols) * field.rows, 0);
  const int corners = static_cast<int>(polygon.size());
  std::vector<double> crossings;
  for (int r = 0; r < field.rows; ++r) {
    const double y = field.origin.y() + field.cell_mm * (r + 0.5);
    crossings.clear();
    for (int i = 0; i < corners; ++i) {
      const Eigen::Vector2d& a = polygon[i];
      const Eigen::Vector2d& b = polygon[(i + 1) % corners];
      if ((a.y() > y) != (b.y() > y))
        crossings.push_back(a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
    }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
      // Cells whose centre x lies in [crossings[k], crossings[k + 1]).
      const double first = (crossings[k] - field.origin.x()) / field.cell_mm - 0.5;
      const double last = (crossings[k + 1] - field.origin.x()) / field.cell_mm - 0.5;
      const int c0 = std::max(0, static_cast<int>(std::ceil(first)));
      const int c1 = std::min(field.cols - 1, static_cast<int>(std::ceil(last)) - 1);
      for (int c = c0; c <= c1; ++c) inside[static_cast<std::size_t>(r) * field.cols + c] = 1;
    }
  }
  return inside;
}

std::vector<int> EnclosedHoles(const GridField& field) {
  const int n = field.cols * field.rows;
  assert(static_cast<int>(field.value.size()) == n);
  std::vector<int> label(n, kOpen);
  std::vector<char> seen(n, 0);
  int holes = 0;
  for (int seed = 0; seed < n; ++seed) {
    if (seen[seed] || Known(field, seed)) continue;
    // Flood the unknown component from `seed`; it is a hole unless it reaches the border.
    std::vector<int> component = {seed}, stack = {seed};
    seen[seed] = 1;
    bool open = false;
    while (!stack.empty()) {
      const int cell = stack.back();
      stack.pop_back();
      open = open || OnBorder(field, cell);
      for (int next : Neighbours(field, cell))
        if (!seen[next] && !Known(field, next)) {
          seen[next] = 1;
          component.push_back(next);
          stack.push_back(next);
        }
    }
    if (open) continue;
    for (int cell : component) label[cell] = holes;
    ++holes;
  }
  return label;
}

FilledField FillHoles(const GridField& field) {
  const int n = field.cols * field.rows;
  const std::vector<int> hole = EnclosedHoles(field);
  std::vector<int> unknown_index(n, -1);
  int unknowns = 0;
  for (int i = 0; i < n; ++i)
    if (hole[i] != kOpen) unknown_index[i] = unknowns++;
  FilledField out{field.value, field.value};
  if (unknowns == 0) return out;

  // One row per 5-point Laplacian: u(N) + u(S) + u(E) + u(W) - 4 u(centre),
  // unknowns on the left, known values moved to the right.
  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> entries;
  std::vector<double> rhs;
  auto add_row = [&](int centre) {
    if (OnBorder(field, centre)) return;
    const std::array<int, 5> cells = {centre, centre - 1, centre + 1, centre - field.cols,
                                      centre + field.cols};
    const std::array<double, 5> weights = {-4.0, 1.0, 1.0, 1.0, 1.0};
    double b = 0.0;
    for (int k = 0; k < 5; ++k) {
      const int cell = cells[k];
      if (unknown_index[cell] < 0 && !Known(field, cell)) return;  // an open unknown in the stencil
      if (unknown_index[cell] < 0) b -= weights[k] * field.value[cell];
    }
    const int row = static_cast<int>(rhs.size());
    for (int k = 0; k < 5; ++k)
      if (unknown_index[cells[k]] >= 0)
        entries.emplace_back(row, unknown_index[cells[k]], weights[k]);
    rhs.push_back(b);
  };
  // The membrane's equations first, one per hole cell in the unknowns'
  // order (a square system); then, for the thin plate, the known cells on a
  // hole's rim: their Laplacian, too, is kept small, which carries the slope
  // across the rim.
  for (int i = 0; i < n; ++i)
    if (unknown_index[i] >= 0) add_row(i);
  const int membrane_rows = static_cast<int>(rhs.size());
  for (int i = 0; i < n; ++i) {
    if (unknown_index[i] >= 0 || !Known(field, i)) continue;
    for (int next : Neighbours(field, i))
      if (unknown_index[next] >= 0) {
        add_row(i);
        break;
      }
  }
  Eigen::SparseMatrix<double> a(static_cast<int>(rhs.size()), unknowns);
  a.setFromTriplets(entries.begin(), entries.end());
  const Eigen::VectorXd b = Eigen::Map<const Eigen::VectorXd>(rhs.data(), rhs.size());

  // Membrane: -Laplacian with a Dirichlet rim, positive definite.
  const Eigen::SparseMatrix<double> negated = -a.topRows(membrane_rows);
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> membrane(negated);
  assert(membrane.info() == Eigen::Success);
  const Eigen::VectorXd um = membrane.solve(-b.head(membrane_rows));
  // Thin plate: least squares over all rows (holds the membrane's full-rank ones).
  const Eigen::SparseMatrix<double> normal = a.transpose() * a;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> plate(normal);
  assert(plate.info() == Eigen::Success);
  const Eigen::VectorXd up = plate.solve(a.transpose() * b);
  for (int i = 0; i < n; ++i)
    if (unknown_index[i] >= 0) {
      out.thin_plate[i] = up[unknown_index[i]];
      out.membrane[i] = um[unknown_index[i]];
    }
  return out;
}

}  // namespace bsls::measurement::internal
