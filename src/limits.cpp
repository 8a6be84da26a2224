#include "trivox/limits.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <mutex>

#include "trivox/error.hpp"

namespace trivox {

namespace {

constexpr std::array<LimitInfo, 6> table = {{
    {"max_file_bytes", &Limits::max_file_bytes, "bytes of a model file"},
    {"max_order", &Limits::max_order, "order (degree + 1) per direction of a cell, surface or curve"},
    {"max_points", &Limits::max_points, "control points of one cell, surface or curve"},
    {"max_cells", &Limits::max_cells, "cells and surfaces in a model, trimming cells included"},
    {"max_name_bytes", &Limits::max_name_bytes, "bytes of a cell, surface or property name"},
    {"max_properties", &Limits::max_properties, "properties per control point"},
}};

std::string names() {
  std::string s;
  for (const auto& l : table) s += (s.empty() ? "" : ", ") + std::string(l.name);
  return s;
}

/// The process default. A lock, not atomics: a Limits is copied whole, once per file read.
std::mutex default_mutex;
Limits default_value;

}  // namespace

std::span<const LimitInfo> limit_table() noexcept { return table; }

std::string limit_hint(std::string_view name) {
  const std::string n(name);
  return " (limit " + n + "; raise it with --limit " + n + "=N)";
}

void set_limit(Limits& limits, std::string_view assignment, const std::string& source) {
  const std::string text(assignment);
  const auto eq = assignment.find('=');
  if (eq == std::string_view::npos)
    throw Error(source + " " + text + ": no '='; expected NAME=N with NAME one of " + names());
  const std::string_view name = assignment.substr(0, eq), value = assignment.substr(eq + 1);
  const LimitInfo* info = nullptr;
  for (const auto& l : table)
    if (name == l.name) info = &l;
  if (info == nullptr)
    throw Error(source + " " + text + ": unknown limit \"" + std::string(name) + "\"; expected one of " + names());
  // A whole number 1..1e18, plainly or in exponent form ("1e9", "2.5e6"): what the docs write.
  double v = 0;
  const auto r = std::from_chars(value.data(), value.data() + value.size(), v);
  if (value.empty() || r.ec != std::errc() || r.ptr != value.data() + value.size() || !(v >= 1) || v > 1e18 ||
      v != std::floor(v))
    throw Error(source + " " + text + ": \"" + std::string(value) + "\" is not a whole number from 1 to 1e18; expected " +
                std::string(info->name) + "=N with N from 1 to 1e18 (the " + info->bounds + ")");
  limits.*(info->field) = static_cast<std::int64_t>(v);
}

void set_limits(Limits& limits, std::string_view list, const std::string& source) {
  while (!list.empty()) {
    const auto comma = list.find(',');
    const std::string_view item = list.substr(0, comma);
    if (!item.empty()) set_limit(limits, item, source);
    if (comma == std::string_view::npos) break;
    list.remove_prefix(comma + 1);
  }
}

void check_order(std::int64_t order, const Limits& limits, const std::string& what) {
  if (order > limits.max_order)
    throw Error(what + ": order " + std::to_string(order) + "; expected an order of at most " +
                std::to_string(limits.max_order) + limit_hint("max_order"));
}

Limits default_limits() {
  const std::lock_guard lock(default_mutex);
  return default_value;
}

void set_default_limits(const Limits& limits) {
  const std::lock_guard lock(default_mutex);
  default_value = limits;
}

}  // namespace trivox
