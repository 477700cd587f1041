// The lines of a GLSL source the preprocessor keeps: conditional groups (#if, #ifdef, #ifndef,
// #elif, #else, #endif) evaluated with the object-like macros the source defines before them
// (#define NAME [integer expression], #undef), so that a `discard` or a `gl_FragDepth` in a branch
// the compiler drops does not count (the interposer's flags, interposer.cpp). Header only, no
// dependencies: the interposer is loaded into other processes.
//
// Conservative where it cannot decide: a condition it cannot evaluate (a function-like macro, an
// operator it does not know, a macro whose value is not an integer expression) keeps every branch
// of its group, so a flag is never cleared by a guess. Comments are removed first; line
// continuations are joined.
#pragma once

#include <cctype>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace nbsim::apitrace {

namespace glsl_detail {

inline std::string without_comments(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    if (s.compare(i, 2, "//") == 0) {
      while (i < s.size() && s[i] != '\n') ++i;
    } else if (s.compare(i, 2, "/*") == 0) {
      const std::size_t end = s.find("*/", i + 2);
      for (std::size_t k = i; k < (end == std::string_view::npos ? s.size() : end); ++k)
        if (s[k] == '\n') out += '\n';  // keep the line count
      i = end == std::string_view::npos ? s.size() : end + 2;
      out += ' ';
    } else if (s[i] == '\\' && i + 1 < s.size() && s[i + 1] == '\n') {
      i += 2;  // a continued line
    } else {
      out += s[i++];
    }
  }
  return out;
}

inline bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// A name the compiler may define itself (__VERSION__, GL_core_profile, GL_ES, GL_ARB_... for each
// extension it supports): its value is unknown here unless the source defined it.
inline bool compiler_name(std::string_view name) { return name.rfind("GL_", 0) == 0 || name.rfind("__", 0) == 0; }

// An integer expression of #if / #elif: C's operators on 64-bit integers; nullopt when it cannot
// be evaluated.
class Expression {
 public:
  Expression(std::string_view text, const std::map<std::string, std::string>& macros, int depth = 0)
      : s_(text), macros_(macros), depth_(depth) {}

  std::optional<std::int64_t> evaluate() {
    if (depth_ > 16) return std::nullopt;  // macros expanding into each other
    const auto v = logical_or();
    skip();
    if (!v || at_ != s_.size()) return std::nullopt;
    return v;
  }

 private:
  void skip() {
    while (at_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[at_]))) ++at_;
  }
  bool eat(std::string_view op) {
    skip();
    if (s_.compare(at_, op.size(), op) != 0) return false;
    // "&" is not "&&", "<" is not "<=" or "<<", "=" alone is no operator here.
    if (op.size() == 1 && at_ + 1 < s_.size()) {
      const char n = s_[at_ + 1];
      if ((op == "&" && n == '&') || (op == "|" && n == '|') || ((op == "<" || op == ">") && (n == '=' || n == op[0])) ||
          (op == "!" && n == '='))
        return false;
    }
    at_ += op.size();
    return true;
  }
  std::optional<std::int64_t> logical_or() {
    auto v = logical_and();
    while (v && eat("||")) {
      const auto r = logical_and();
      if (!r) return std::nullopt;
      v = (*v != 0 || *r != 0) ? 1 : 0;
    }
    return v;
  }
  std::optional<std::int64_t> logical_and() {
    auto v = bit_or();
    while (v && eat("&&")) {
      const auto r = bit_or();
      if (!r) return std::nullopt;
      v = (*v != 0 && *r != 0) ? 1 : 0;
    }
    return v;
  }
  std::optional<std::int64_t> bit_or() {
    auto v = bit_and();
    while (v && eat("|")) {
      const auto r = bit_and();
      if (!r) return std::nullopt;
      v = *v | *r;
    }
    return v;
  }
  std::optional<std::int64_t> bit_and() {
    auto v = equality();
    while (v && eat("&")) {
      const auto r = equality();
      if (!r) return std::nullopt;
      v = *v & *r;
    }
    return v;
  }
  std::optional<std::int64_t> equality() {
    auto v = relational();
    for (;;) {
      if (!v) return v;
      if (eat("==")) {
        const auto r = relational();
        if (!r) return std::nullopt;
        v = *v == *r ? 1 : 0;
      } else if (eat("!=")) {
        const auto r = relational();
        if (!r) return std::nullopt;
        v = *v != *r ? 1 : 0;
      } else {
        return v;
      }
    }
  }
  std::optional<std::int64_t> relational() {
    auto v = additive();
    for (;;) {
      if (!v) return v;
      std::optional<std::int64_t> r;
      if (eat("<=")) {
        if (!(r = additive())) return std::nullopt;
        v = *v <= *r ? 1 : 0;
      } else if (eat(">=")) {
        if (!(r = additive())) return std::nullopt;
        v = *v >= *r ? 1 : 0;
      } else if (eat("<")) {
        if (!(r = additive())) return std::nullopt;
        v = *v < *r ? 1 : 0;
      } else if (eat(">")) {
        if (!(r = additive())) return std::nullopt;
        v = *v > *r ? 1 : 0;
      } else {
        return v;
      }
    }
  }
  std::optional<std::int64_t> additive() {
    auto v = multiplicative();
    for (;;) {
      if (!v) return v;
      std::optional<std::int64_t> r;
      if (eat("+")) {
        if (!(r = multiplicative())) return std::nullopt;
        v = *v + *r;
      } else if (eat("-")) {
        if (!(r = multiplicative())) return std::nullopt;
        v = *v - *r;
      } else {
        return v;
      }
    }
  }
  std::optional<std::int64_t> multiplicative() {
    auto v = unary();
    for (;;) {
      if (!v) return v;
      std::optional<std::int64_t> r;
      if (eat("*")) {
        if (!(r = unary())) return std::nullopt;
        v = *v * *r;
      } else if (eat("/") || eat("%")) {
        const char op = s_[at_ - 1];
        if (!(r = unary()) || *r == 0) return std::nullopt;
        v = op == '/' ? *v / *r : *v % *r;
      } else {
        return v;
      }
    }
  }
  std::optional<std::int64_t> unary() {
    if (eat("!")) {
      const auto v = unary();
      return v ? std::optional<std::int64_t>(*v == 0 ? 1 : 0) : std::nullopt;
    }
    if (eat("-")) {
      const auto v = unary();
      return v ? std::optional<std::int64_t>(-*v) : std::nullopt;
    }
    if (eat("+")) return unary();
    if (eat("~")) {
      const auto v = unary();
      return v ? std::optional<std::int64_t>(~*v) : std::nullopt;
    }
    return primary();
  }
  std::optional<std::int64_t> primary() {
    skip();
    if (eat("(")) {
      const auto v = logical_or();
      if (!v || !eat(")")) return std::nullopt;
      return v;
    }
    if (at_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[at_]))) {
      std::size_t end = at_;
      while (end < s_.size() && ident_char(s_[end])) ++end;
      std::string digits(s_.substr(at_, end - at_));
      while (!digits.empty() && (digits.back() == 'u' || digits.back() == 'U' || digits.back() == 'l' || digits.back() == 'L')) digits.pop_back();
      at_ = end;
      try {
        std::size_t used = 0;
        const std::int64_t v = std::stoll(digits, &used, 0);
        if (used != digits.size()) return std::nullopt;
        return v;
      } catch (...) {
        return std::nullopt;
      }
    }
    if (at_ < s_.size() && ident_char(s_[at_])) {
      std::size_t end = at_;
      while (end < s_.size() && ident_char(s_[end])) ++end;
      const std::string name(s_.substr(at_, end - at_));
      at_ = end;
      if (name == "defined") {
        const bool paren = eat("(");
        skip();
        std::size_t e = at_;
        while (e < s_.size() && ident_char(s_[e])) ++e;
        if (e == at_) return std::nullopt;
        const std::string what(s_.substr(at_, e - at_));
        const bool is = macros_.count(what) != 0;
        at_ = e;
        if (!is && compiler_name(what)) return std::nullopt;
        if (paren && !eat(")")) return std::nullopt;
        return is ? 1 : 0;
      }
      skip();
      if (at_ < s_.size() && s_[at_] == '(') return std::nullopt;  // a function-like macro call
      const auto m = macros_.find(name);
      if (m == macros_.end()) return compiler_name(name) ? std::nullopt : std::optional<std::int64_t>(0);  // an undefined identifier is 0
      if (m->second.empty()) return std::nullopt;  // defined as nothing: not a value
      return Expression(m->second, macros_, depth_ + 1).evaluate();
    }
    return std::nullopt;
  }

  std::string_view s_;
  const std::map<std::string, std::string>& macros_;
  int depth_;
  std::size_t at_ = 0;
};

}  // namespace glsl_detail

// The source's active text: comments removed, the lines of every group the preprocessor drops
// blanked, directives themselves blanked. `predefined`: macros defined before the source (the
// compiler's, e.g. GL_core_profile), by name and value.
inline std::string glsl_active_text(std::string_view source, const std::map<std::string, std::string>& predefined = {}) {
  using namespace glsl_detail;
  const std::string text = without_comments(source);
  std::map<std::string, std::string> macros = predefined;
  // One entry per open group: whether its current branch is kept, whether an earlier branch was
  // certainly taken (its condition decided true: every later branch is dropped; an undecidable one
  // is kept and keeps the later ones open), and whether the group's parent is kept.
  struct Group {
    bool keep, done, parent;
  };
  std::vector<Group> groups;
  const auto kept = [&] { return groups.empty() || groups.back().keep; };
  std::string out;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + start, end - start);
    std::size_t p = 0;
    while (p < line.size() && (line[p] == ' ' || line[p] == '\t')) ++p;
    if (p < line.size() && line[p] == '#') {
      ++p;
      while (p < line.size() && (line[p] == ' ' || line[p] == '\t')) ++p;
      std::size_t q = p;
      while (q < line.size() && ident_char(line[q])) ++q;
      const std::string_view directive = line.substr(p, q - p);
      std::string_view rest = line.substr(q);
      const auto first_word = [](std::string_view r) {
        std::size_t a = 0;
        while (a < r.size() && (r[a] == ' ' || r[a] == '\t')) ++a;
        std::size_t b = a;
        while (b < r.size() && ident_char(r[b])) ++b;
        return std::string(r.substr(a, b - a));
      };
      const auto condition = [&](std::string_view expr) -> std::optional<bool> {
        const auto v = Expression(expr, macros).evaluate();
        if (!v) return std::nullopt;
        return *v != 0;
      };
      const auto open = [&](std::optional<bool> c) {
        const bool parent = kept();
        groups.push_back({parent && (!c || *c), c.value_or(false), parent});
      };
      if (directive == "if") {
        open(condition(rest));
      } else if (directive == "ifdef" || directive == "ifndef") {
        const std::string name = first_word(rest);
        const bool is = macros.count(name) != 0;
        if (!is && compiler_name(name)) open(std::nullopt);
        else open(directive == "ifdef" ? is : !is);
      } else if ((directive == "elif" || directive == "else") && !groups.empty()) {
        Group& g = groups.back();
        const std::optional<bool> c = directive == "else" ? std::optional<bool>(true) : condition(rest);
        g.keep = !g.done && g.parent && (!c || *c);
        g.done = g.done || c.value_or(false);
      } else if (directive == "endif" && !groups.empty()) {
        groups.pop_back();
      } else if (directive == "define" && kept()) {
        std::size_t a = 0;
        while (a < rest.size() && (rest[a] == ' ' || rest[a] == '\t')) ++a;
        std::size_t b = a;
        while (b < rest.size() && ident_char(rest[b])) ++b;
        const std::string name(rest.substr(a, b - a));
        std::string value;
        if (b < rest.size() && rest[b] == '(') {
          value = "";  // function-like: never a value
        } else {
          value = std::string(rest.substr(b));
          while (!value.empty() && std::isspace(static_cast<unsigned char>(value.front()))) value.erase(value.begin());
          while (!value.empty() && std::isspace(static_cast<unsigned char>(value.back()))) value.pop_back();
        }
        if (!name.empty()) macros[name] = value;
      } else if (directive == "undef" && kept()) {
        macros.erase(first_word(rest));
      }
      out += '\n';
    } else {
      if (kept()) out.append(line);
      out += '\n';
    }
    if (end == text.size()) break;
    start = end + 1;
  }
  return out;
}

}  // namespace nbsim::apitrace
