#include "model_scan.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "trivox/error.hpp"

namespace trivox::io {

namespace {

/// What a container holds, from its key or its parent's role.
enum class Role : std::uint8_t {
  other,
  properties,   ///< the top-level "properties" array
  orders,       ///< a spline's "orders"
  knots,        ///< a spline's "knots": an array of knot vectors
  knot_vector,  ///< one of them
  points,       ///< a spline's "points"
};

/// What a spline object declared so far (an object holding "orders", "knots" or "points").
struct Spline {
  static constexpr int max_dims = 4;
  bool checkable = true;  ///< false once anything is malformed: the reader will say what
  int orders_seen = -1;   ///< -1: no "orders" yet
  std::int64_t orders[max_dims] = {};
  int knots_seen = -1;
  std::int64_t knot_counts[max_dims] = {};
  std::int64_t points = -1;
  std::int64_t max_run = 0;  ///< the longest run of equal knots in any knot vector
};

struct Frame {
  bool object = false;
  Role role = Role::other;
  std::size_t index = 0;  ///< arrays: elements begun; objects: unused
  std::string key;        ///< objects: the current key
  Spline spline;          ///< objects: what they declared as a spline
  // Arrays of numbers the pass reads: orders, a knot vector.
  std::int64_t values[Spline::max_dims] = {};
  bool good = true;       ///< every element so far well formed (whole orders; ordered knots)
  double last = 0;        ///< knot vectors: the previous knot
  std::int64_t run = 0;   ///< its multiplicity so far
  std::int64_t max_run = 0;
};

/// A string token's text in quotes again, for the parser. Appended piecewise: GCC 12 warns falsely
/// (-Wrestrict) on "\"" + std::string(s) + "\"".
std::string quoted(std::string_view raw) {
  std::string s;
  s.reserve(raw.size() + 2);
  s.append(1, '"').append(raw).append(1, '"');
  return s;
}

std::string plural(std::int64_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

class Scanner {
public:
  Scanner(std::string_view text, const std::string& source, const Limits& limits)
      : text_(text), source_(source), limits_(limits) {}

  /// True when the pass followed the text to the end of its one value.
  bool run();

private:
  std::string_view text_;
  const std::string& source_;
  const Limits& limits_;
  std::vector<Frame> stack_;
  std::size_t i_ = 0;
  std::int64_t cells_ = 0;

  /// The pointer of the container at depth `depth` (stack_[depth - 1]'s current child).
  std::string pointer(std::size_t depth) const {
    std::string p;
    for (std::size_t d = 0; d < depth && d < stack_.size(); ++d) {
      const Frame& f = stack_[d];
      if (d + 1 == depth) break;
      p += "/" + (f.object ? f.key : std::to_string(f.index - 1));
    }
    return p;
  }
  /// The pointer of the value being read (the current child of the innermost container).
  std::string here() const {
    std::string p;
    for (const Frame& f : stack_) p += "/" + (f.object ? f.key : std::to_string(f.index - 1));
    return p;
  }
  /// The pointer of the innermost container itself.
  std::string container() const { return pointer(stack_.size()); }

  [[noreturn]] void fail(const std::string& ptr, const std::string& what, const char* limit) const {
    throw Error(source_ + ": " + (ptr.empty() ? std::string("top level") : ptr) + ": " + what +
                (limit ? limit_hint(limit) : std::string()));
  }

  void skip_space() {
    while (i_ < text_.size() && (text_[i_] == ' ' || text_[i_] == '\n' || text_[i_] == '\r' || text_[i_] == '\t')) ++i_;
  }

  /// The raw text of a string token at i_ (on its opening quote), i_ moved past it; false when
  /// unterminated.
  bool string_token(std::string_view& raw, bool& escaped) {
    const std::size_t start = ++i_;
    escaped = false;
    while (i_ < text_.size()) {
      const char c = text_[i_];
      if (c == '"') {
        raw = text_.substr(start, i_ - start);
        ++i_;
        return true;
      }
      if (c == '\\') escaped = true, ++i_;
      ++i_;
    }
    return false;
  }

  /// The role of a container or value starting as the current child of the innermost frame.
  Role child_role() const {
    if (stack_.empty()) return Role::other;
    const Frame& f = stack_.back();
    if (f.object) {
      if (stack_.size() == 1 && f.key == "properties") return Role::properties;
      if (f.key == "orders") return Role::orders;
      if (f.key == "knots") return Role::knots;
      if (f.key == "points") return Role::points;
      return Role::other;
    }
    return f.role == Role::knots ? Role::knot_vector : Role::other;
  }

  /// A new element of the innermost array (or value of the current key) begins.
  void begin_value() {
    if (stack_.empty() || stack_.back().object) return;
    Frame& f = stack_.back();
    ++f.index;
    const auto n = static_cast<std::int64_t>(f.index);
    if (f.role == Role::points && n > limits_.max_points)
      fail(container(), "more than " + plural(limits_.max_points, "control point") + "; expected at most " +
                            std::to_string(limits_.max_points) + " per cell, surface or curve", "max_points");
    if (f.role == Role::knot_vector && n > limits_.max_points + limits_.max_order)
      fail(container(), "more than " + plural(limits_.max_points + limits_.max_order, "knot") + "; expected at most " +
                            std::to_string(limits_.max_points + limits_.max_order) +
                            " (max_points control points + max_order)", "max_points");
    if (f.role == Role::properties && n > limits_.max_properties)
      fail(container(), "more than " + std::to_string(limits_.max_properties) + " properties; expected at most " +
                            std::to_string(limits_.max_properties), "max_properties");
    if (f.role == Role::orders && n > Spline::max_dims) f.good = false;
  }

  void on_key(const std::string& key) {
    if (key == "trivariate" || key == "surface") {
      if (++cells_ > limits_.max_cells)
        fail(container(), "more than " + plural(limits_.max_cells, "cell") + " and surfaces; expected at most " +
                              std::to_string(limits_.max_cells) + " cells and surfaces, trimming cells included",
             "max_cells");
    }
  }

  void on_string(std::string_view raw, bool escaped) {
    if (stack_.empty()) return;
    const Frame& f = stack_.back();
    const bool name = (f.object && f.key == "name") || (!f.object && f.role == Role::properties);
    if (!name || static_cast<std::int64_t>(raw.size()) <= limits_.max_name_bytes) return;
    std::int64_t bytes = static_cast<std::int64_t>(raw.size());
    if (escaped) {  // escapes are longer than what they stand for: decode this one string
      const auto j = nlohmann::json::parse(quoted(raw), nullptr, false);
      if (!j.is_string()) return;
      bytes = static_cast<std::int64_t>(j.get_ref<const std::string&>().size());
      if (bytes <= limits_.max_name_bytes) return;
    }
    fail(here(), "a name of " + std::to_string(bytes) + " bytes; expected at most " +
                     std::to_string(limits_.max_name_bytes) + " bytes", "max_name_bytes");
  }

  void on_number(std::string_view token) {
    if (stack_.empty() || stack_.back().object) return;
    Frame& f = stack_.back();
    if (f.role != Role::orders && f.role != Role::knot_vector) return;
    double v = 0;
    const auto r = std::from_chars(token.data(), token.data() + token.size(), v);
    const bool number = r.ec == std::errc() && r.ptr == token.data() + token.size() && std::isfinite(v);
    if (f.role == Role::orders) {
      if (number && v > static_cast<double>(limits_.max_order))
        fail(here(), (token.size() > 24 ? "a number above " + std::to_string(limits_.max_order) : std::string(token)) +
                         "; expected an order of at most " + std::to_string(limits_.max_order),
             "max_order");
      if (!number || v < 1 || v != std::floor(v)) f.good = false;
      else if (f.index <= static_cast<std::size_t>(Spline::max_dims)) f.values[f.index - 1] = static_cast<std::int64_t>(v);
      return;
    }
    // A knot.
    if (!number) {
      f.good = false;
      return;
    }
    if (f.index > 1 && v < f.last) f.good = false;
    f.run = (f.index > 1 && v == f.last) ? f.run + 1 : 1;
    f.max_run = std::max(f.max_run, f.run);
    f.last = v;
  }

  /// The innermost container closes: hand what it gathered to its spline object.
  void close_container() {
    Frame f = std::move(stack_.back());
    stack_.pop_back();
    if (f.object) {
      check_spline(f.spline, f);
      return;
    }
    if (stack_.empty()) return;
    Frame& parent = stack_.back();
    switch (f.role) {
      case Role::orders: {
        Spline& s = parent.spline;
        if (!f.good || f.index > static_cast<std::size_t>(Spline::max_dims)) s.checkable = false;
        s.orders_seen = static_cast<int>(std::min<std::size_t>(f.index, Spline::max_dims));
        for (int d = 0; d < s.orders_seen; ++d) s.orders[d] = f.values[d];
        check_spline(s, parent);
        break;
      }
      case Role::knot_vector: {
        // parent is the knots array: its values[] collect the counts of control points.
        if (parent.index > static_cast<std::size_t>(Spline::max_dims)) {
          parent.good = false;
          break;
        }
        parent.values[parent.index - 1] = static_cast<std::int64_t>(f.index);
        if (!f.good) parent.good = false;
        parent.max_run = std::max(parent.max_run, f.max_run);
        break;
      }
      case Role::knots: {
        Spline& s = parent.spline;
        if (!f.good || f.index > static_cast<std::size_t>(Spline::max_dims)) s.checkable = false;
        s.knots_seen = static_cast<int>(std::min<std::size_t>(f.index, Spline::max_dims));
        for (int d = 0; d < s.knots_seen; ++d) s.knot_counts[d] = f.values[d];
        s.max_run = f.max_run;  // compared with the orders once both are known
        check_spline(s, parent);
        break;
      }
      case Role::points: {
        parent.spline.points = static_cast<std::int64_t>(f.index);
        check_spline(parent.spline, parent);
        break;
      }
      default: break;
    }
  }

  /// Once orders and knots are known: the control points they give, against max_points and
  /// against the "points" array's length (once known).
  void check_spline(const Spline& s, const Frame& object) {
    if (!s.checkable || s.orders_seen < 1 || s.knots_seen != s.orders_seen) return;
    std::int64_t highest = 1;
    for (int d = 0; d < s.orders_seen; ++d) highest = std::max(highest, s.orders[d]);
    if (s.max_run > highest) return;  // a multiplicity the reader refuses
    std::int64_t count = 1;
    std::string counts_text;
    bool over = false;
    for (int d = 0; d < s.orders_seen; ++d) {
      const std::int64_t n = s.knot_counts[d] - s.orders[d];
      if (s.knot_counts[d] < 2 * s.orders[d]) return;  // the reader's "at least 2 x order" message
      over = over || (n != 0 && count > limits_.max_points / n);
      count = over ? limits_.max_points + 1 : count * n;
      counts_text += (d ? " x " : "") + std::to_string(n);
    }
    const std::string base = object_pointer(object);
    if (count > limits_.max_points)
      fail(base + "/knots", counts_text + " control points (from the knot vectors and orders); expected at most " +
                                std::to_string(limits_.max_points) + " per cell, surface or curve",
           "max_points");
    if (s.points >= 0 && s.points != count)
      fail(base + "/points", plural(s.points, "control point") + "; expected " + std::to_string(count) + " (" +
                                 counts_text + ", from the knot vectors and orders)",
           nullptr);
  }

  /// The pointer of a spline object: the innermost frame when it is still open, else the one
  /// just closed (its parent's current child).
  std::string object_pointer(const Frame& object) const {
    if (!stack_.empty() && &stack_.back() == &object) return container();
    return here();
  }

  /// Skips a number or literal; its text.
  std::string_view scalar_token() {
    const std::size_t start = i_;
    while (i_ < text_.size()) {
      const char c = text_[i_];
      if (c == ',' || c == ']' || c == '}' || c == ' ' || c == '\n' || c == '\r' || c == '\t') break;
      ++i_;
    }
    return text_.substr(start, i_ - start);
  }
};

bool Scanner::run() {
  if (text_.starts_with("\xEF\xBB\xBF")) i_ = 3;  // a UTF-8 byte-order mark, as the parser skips it
  bool expect_value = true;  // else: a ',' or a closing bracket, or (in objects) a key
  bool expect_key = false;
  while (true) {
    skip_space();
    if (i_ >= text_.size()) return false;
    const char c = text_[i_];
    if (expect_key) {
      if (c == '}') {
        ++i_;
        close_container();
        expect_key = false;
        expect_value = false;
        if (stack_.empty()) return true;
        continue;
      }
      if (c != '"') return false;
      std::string_view raw;
      bool escaped = false;
      if (!string_token(raw, escaped)) return false;
      std::string key(raw);
      if (escaped) {
        const auto j = nlohmann::json::parse(quoted(raw), nullptr, false);
        if (!j.is_string()) return false;
        key = j.get<std::string>();
      }
      skip_space();
      if (i_ >= text_.size() || text_[i_] != ':') return false;
      ++i_;
      stack_.back().key = std::move(key);
      on_key(stack_.back().key);
      expect_key = false;
      expect_value = true;
      continue;
    }
    if (expect_value) {
      if (c == ']' && !stack_.empty() && !stack_.back().object && stack_.back().index == 0) {
        ++i_;
        close_container();
        expect_value = false;
        if (stack_.empty()) return true;
        continue;
      }
      const Role role = child_role();
      begin_value();
      // Orders and knots hold numbers only; anything else is the reader's to report.
      if (!stack_.empty() && !stack_.back().object && c != '-' && (c < '0' || c > '9') &&
          (stack_.back().role == Role::orders || stack_.back().role == Role::knot_vector))
        stack_.back().good = false;
      if (c == '{' || c == '[') {
        ++i_;
        Frame f;
        f.object = c == '{';
        f.role = f.object ? Role::other : role;
        stack_.push_back(std::move(f));
        if (c == '{') expect_key = true, expect_value = false;
        continue;
      }
      if (c == '"') {
        std::string_view raw;
        bool escaped = false;
        if (!string_token(raw, escaped)) return false;
        on_string(raw, escaped);
      } else {
        const std::string_view token = scalar_token();
        if (token.empty()) return false;
        on_number(token);
      }
      expect_value = false;
      if (stack_.empty()) return true;
      continue;
    }
    // After a value.
    if (stack_.empty()) return true;
    if (c == ',') {
      ++i_;
      if (stack_.back().object) expect_key = true;
      else expect_value = true;
      continue;
    }
    if ((c == '}' && stack_.back().object) || (c == ']' && !stack_.back().object)) {
      ++i_;
      close_container();
      if (stack_.empty()) return true;
      continue;
    }
    return false;  // malformed: the reader reports it
  }
}

}  // namespace

bool scan_model_json(std::string_view text, const std::string& source, const Limits& limits) {
  return Scanner(text, source, limits).run();
}

}  // namespace trivox::io
