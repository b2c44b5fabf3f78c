#include "fe/quadrature.hpp"

#include <array>

#include "core/error.hpp"

namespace shroudsim::fe {
namespace {

// Adds the points of one symmetry orbit given in barycentric coordinates (l0, l1, l2, l3);
// reference coordinates are (l1, l2, l3).
void add_orbit(TetQuadrature& q, const std::vector<std::array<double, 4>>& bary, double weight) {
  for (const auto& l : bary) {
    q.points.emplace_back(l[1], l[2], l[3]);
    q.weights.push_back(weight);
  }
}

std::vector<std::array<double, 4>> orbit_aaab(double a) {  // (a, a, a, 1 - 3a): 4 points
  const double b = 1.0 - 3.0 * a;
  return {{b, a, a, a}, {a, b, a, a}, {a, a, b, a}, {a, a, a, b}};
}

std::vector<std::array<double, 4>> orbit_aabb(double a) {  // (a, a, b, b), b = 1/2 - a: 6 points
  const double b = 0.5 - a;
  return {{a, a, b, b}, {a, b, a, b}, {a, b, b, a}, {b, a, a, b}, {b, a, b, a}, {b, b, a, a}};
}

TetQuadrature make_degree1() {
  TetQuadrature q;
  q.degree = 1;
  add_orbit(q, {{0.25, 0.25, 0.25, 0.25}}, 1.0 / 6.0);
  return q;
}

TetQuadrature make_degree2() {
  TetQuadrature q;
  q.degree = 2;
  add_orbit(q, orbit_aaab(0.1381966011250105), 1.0 / 24.0);  // a = (5 - sqrt 5) / 20
  return q;
}

TetQuadrature make_degree5() {
  // Walkington's 14-point degree-5 rule (positive weights).
  TetQuadrature q;
  q.degree = 5;
  add_orbit(q, orbit_aaab(0.0927352503108912), 0.01224884051939366);
  add_orbit(q, orbit_aaab(0.3108859192633006), 0.01878132095300264);
  add_orbit(q, orbit_aabb(0.4544962958743504), 0.007091003462846911);
  return q;
}

}  // namespace

const TetQuadrature& tet_quadrature(int degree) {
  static const TetQuadrature q1 = make_degree1();
  static const TetQuadrature q2 = make_degree2();
  static const TetQuadrature q5 = make_degree5();
  SHROUDSIM_CHECK(degree >= 0 && degree <= 5, "tet_quadrature: degree must be in 0..5");
  if (degree <= 1) return q1;
  if (degree == 2) return q2;
  return q5;
}

}  // namespace shroudsim::fe
