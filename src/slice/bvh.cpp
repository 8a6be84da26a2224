// The locator's bounding-volume hierarchy (bvh.hpp): median splits along the longest axis,
// O(n log n) to build over n leaves; a query descends the nodes whose boxes, grown by the pad,
// meet the query box and returns the leaves whose boxes do, sorted (so in cell order).
#include "bvh.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <vector>

namespace trivox::slice {

namespace detail {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

using Data = Locator::Data;

}  // namespace

void build_bvh(Data& D) {
  const int n = static_cast<int>(D.leaves.size());
  D.items.resize(static_cast<std::size_t>(n));
  std::iota(D.items.begin(), D.items.end(), 0);
  D.nodes.clear();
  if (n == 0) return;
  auto centre = [&](int i, int d) {
    const auto& l = D.leaves[static_cast<std::size_t>(i)];
    return l.box_lo[static_cast<std::size_t>(d)] + l.box_hi[static_cast<std::size_t>(d)];
  };
  struct Task {
    int node, first, count;
  };
  D.nodes.push_back({});
  std::vector<Task> stack{{0, 0, n}};
  while (!stack.empty()) {
    const Task t = stack.back();
    stack.pop_back();
    Data::Node nd;
    nd.lo = {inf, inf, inf};
    nd.hi = {-inf, -inf, -inf};
    for (int k = t.first; k < t.first + t.count; ++k) {
      const auto& l = D.leaves[static_cast<std::size_t>(D.items[static_cast<std::size_t>(k)])];
      for (int d = 0; d < 3; ++d) {
        nd.lo[static_cast<std::size_t>(d)] = std::min(nd.lo[static_cast<std::size_t>(d)], l.box_lo[static_cast<std::size_t>(d)]);
        nd.hi[static_cast<std::size_t>(d)] = std::max(nd.hi[static_cast<std::size_t>(d)], l.box_hi[static_cast<std::size_t>(d)]);
      }
    }
    if (t.count <= 4) {
      nd.first = t.first;
      nd.count = t.count;
      D.nodes[static_cast<std::size_t>(t.node)] = nd;
      continue;
    }
    int axis = 0;
    for (int d = 1; d < 3; ++d)
      if (nd.hi[static_cast<std::size_t>(d)] - nd.lo[static_cast<std::size_t>(d)] >
          nd.hi[static_cast<std::size_t>(axis)] - nd.lo[static_cast<std::size_t>(axis)])
        axis = d;
    const int half = t.count / 2;
    auto b = D.items.begin() + t.first;
    std::nth_element(b, b + half, b + t.count, [&](int x, int y) {
      const double cx = centre(x, axis), cy = centre(y, axis);
      return cx < cy || (cx == cy && x < y);
    });
    nd.left = static_cast<int>(D.nodes.size());
    nd.right = nd.left + 1;
    D.nodes.push_back({});
    D.nodes.push_back({});
    D.nodes[static_cast<std::size_t>(t.node)] = nd;
    stack.push_back({nd.left, t.first, half});
    stack.push_back({nd.right, t.first + half, t.count - half});
  }
}

}  // namespace detail

void Locator::query(const Vec3& lo, const Vec3& hi, double pad, std::vector<int>& out) const {
  out.clear();
  const Data& D = *data_;
  if (D.nodes.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  auto overlaps = [&](const Vec3& blo, const Vec3& bhi) {
    for (int d = 0; d < 3; ++d)
      if (bhi[static_cast<std::size_t>(d)] + pad < lo[static_cast<std::size_t>(d)] ||
          blo[static_cast<std::size_t>(d)] - pad > hi[static_cast<std::size_t>(d)])
        return false;
    return true;
  };
  while (top > 0) {
    const auto& nd = D.nodes[static_cast<std::size_t>(stack[--top])];
    if (!overlaps(nd.lo, nd.hi)) continue;
    if (nd.left < 0) {
      for (int k = nd.first; k < nd.first + nd.count; ++k) {
        const int li = D.items[static_cast<std::size_t>(k)];
        const auto& l = D.leaves[static_cast<std::size_t>(li)];
        if (overlaps(l.box_lo, l.box_hi)) out.push_back(li);
      }
      continue;
    }
    stack[top++] = nd.left;
    stack[top++] = nd.right;
  }
  std::sort(out.begin(), out.end());
}

}  // namespace trivox::slice
