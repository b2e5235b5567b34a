// Minimal XML well-formedness checker; see xml_check.hpp.
#include "xml_check.hpp"

#include <algorithm>
#include <cctype>

namespace viz::test {
namespace {

class Checker {
 public:
  Checker(const std::string& s, const std::vector<std::string>& void_tags) : s_(s), void_(void_tags) {}

  XmlCheck run() {
    while (out_.ok && i_ < s_.size()) {
      if (s_[i_] == '<') tag();
      else if (s_[i_] == '&') entity();
      else ++i_;
    }
    if (out_.ok && !stack_.empty()) fail("unclosed <" + stack_.back() + ">");
    return out_;
  }

 private:
  void fail(const std::string& why) {
    if (out_.ok) out_.error = why + " at offset " + std::to_string(i_);
    out_.ok = false;
  }

  void entity() {
    for (const char* e : {"&amp;", "&lt;", "&gt;", "&quot;", "&#39;"})
      if (s_.compare(i_, std::char_traits<char>::length(e), e) == 0) {
        i_ += std::char_traits<char>::length(e);
        return;
      }
    fail("bad entity");
  }

  std::string name() {
    const std::size_t start = i_;
    while (i_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[i_])) || s_[i_] == '-' ||
                              s_[i_] == ':' || s_[i_] == '_'))
      ++i_;
    return s_.substr(start, i_ - start);
  }

  void skip_space() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }

  void skip_to(const std::string& end) {
    const std::size_t at = s_.find(end, i_);
    if (at == std::string::npos) return fail("unterminated declaration");
    i_ = at + end.size();
  }

  void tag() {
    ++i_;
    if (s_.compare(i_, 8, "!DOCTYPE") == 0) return skip_to(">");
    if (s_.compare(i_, 3, "!--") == 0) return skip_to("-->");
    if (i_ < s_.size() && s_[i_] == '/') return end_tag();
    XmlElement e{name(), {}, {}};
    if (e.tag.empty()) return fail("empty tag name");
    for (;;) {
      skip_space();
      if (i_ >= s_.size()) return fail("unterminated tag");
      if (s_.compare(i_, 2, "/>") == 0) { i_ += 2; break; }
      if (s_[i_] == '>') {
        ++i_;
        if (std::find(void_.begin(), void_.end(), e.tag) == void_.end()) stack_.push_back(e.tag);
        e.text = s_.substr(i_, std::min(s_.find('<', i_), s_.size()) - i_);
        break;
      }
      if (!attribute(e)) return;
    }
    out_.elements.push_back(std::move(e));
  }

  bool attribute(XmlElement& e) {
    const std::string key = name();
    if (key.empty() || i_ >= s_.size() || s_[i_] != '=') { fail("attribute without value"); return false; }
    ++i_;
    if (i_ >= s_.size() || s_[i_] != '"') { fail("unquoted attribute " + key); return false; }
    const std::size_t end = s_.find('"', i_ + 1);
    if (end == std::string::npos) { fail("unterminated attribute"); return false; }
    const std::string value = s_.substr(i_ + 1, end - i_ - 1);
    if (value.find('<') != std::string::npos) { fail("'<' in attribute " + key); return false; }
    if (e.attrs.count(key)) { fail("duplicate attribute " + key); return false; }
    e.attrs[key] = value;
    i_ = end + 1;
    return true;
  }

  void end_tag() {
    ++i_;
    const std::string n = name();
    if (i_ >= s_.size() || s_[i_] != '>') return fail("bad end tag");
    ++i_;
    if (stack_.empty() || stack_.back() != n) return fail("mismatched </" + n + ">");
    stack_.pop_back();
  }

  const std::string& s_;
  const std::vector<std::string>& void_;
  std::size_t i_ = 0;
  std::vector<std::string> stack_;
  XmlCheck out_;
};

}  // namespace

XmlCheck check_xml(const std::string& text, const std::vector<std::string>& void_tags) {
  return Checker(text, void_tags).run();
}

std::size_t count_class(const XmlCheck& doc, const std::string& cls) {
  return static_cast<std::size_t>(std::count_if(doc.elements.begin(), doc.elements.end(), [&](const XmlElement& e) {
    auto it = e.attrs.find("class");
    return it != e.attrs.end() && it->second == cls;
  }));
}

std::string first_non_finite_attribute(const XmlCheck& doc) {
  for (const XmlElement& e : doc.elements)
    for (const auto& [name, value] : e.attrs)
      if (value.find("nan") != std::string::npos || value.find("inf") != std::string::npos) return name + "=" + value;
  return {};
}

}  // namespace viz::test
