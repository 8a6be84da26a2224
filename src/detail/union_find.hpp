/// @file src/detail/union_find.hpp
/// @brief Private to trivox_core: disjoint sets of the integers 0..n-1 (path halving, the smaller
/// index as each class's root, so a class's root is its smallest member whatever the join order),
/// shared by the meshers that weld vertices and group faces.
#pragma once
#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace trivox::detail {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[static_cast<std::size_t>(a)] != a) {
      const auto i = static_cast<std::size_t>(a);
      parent[i] = parent[static_cast<std::size_t>(parent[i])];
      a = parent[i];
    }
    return a;
  }
  void join(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace trivox::detail
