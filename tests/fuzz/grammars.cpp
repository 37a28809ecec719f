#include "grammars.h"

#include <yaml-cpp/yaml.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace bsls::fuzz {
namespace {

// ------------------------------------------------------------------ YAML

// A YAML node as the grammar builds it (no sharing: an alias is a node of
// its own kind naming an anchor).
struct Tree {
  enum Kind { kScalar, kSequence, kMap, kAlias } kind = kScalar;
  std::string text;         // scalar text, or the alias's anchor
  std::vector<Tree> items;  // sequence items; map keys and values alternate
  std::string anchor;       // "&name" set on this node, or ""
  bool flow = false;
};

// Scalars a reader must cope with: special floats, numbers at and beyond
// every integer type's ends, empty and null, tags, long and odd text.
const std::vector<std::string>& HostileScalars() {
  static const std::vector<std::string> values = {"0",
                                                  "-1",
                                                  "1",
                                                  "2",
                                                  "8",
                                                  "255",
                                                  "256",
                                                  "65536",
                                                  "2147483647",
                                                  "2147483648",
                                                  "-2147483649",
                                                  "4294967296",
                                                  "9223372036854775807",
                                                  "18446744073709551615",
                                                  "18446744073709551616",
                                                  "1e308",
                                                  "1e309",
                                                  "-1e309",
                                                  "5e-324",
                                                  ".nan",
                                                  ".NaN",
                                                  ".inf",
                                                  "-.inf",
                                                  "0x7fffffff",
                                                  "0o777",
                                                  "~",
                                                  "null",
                                                  "''",
                                                  "\"\"",
                                                  "true",
                                                  "no",
                                                  "left",
                                                  "right",
                                                  "both",
                                                  "!!binary aGVsbG8=",
                                                  "!!int 12",
                                                  "!!str 3",
                                                  "!!float .nan",
                                                  "\"\\u0000\"",
                                                  "\"\\xff\\xfe\"",
                                                  "0660",
                                                  "0666",
                                                  "\"0666\"",
                                                  "/etc/passwd",
                                                  "../../../etc/passwd",
                                                  "t0.png",
                                                  "s0.png",
                                                  "r0.png",
                                                  "bsls-calibration",
                                                  "sha256:" + std::string(64, 'a'),
                                                  std::string(300, 'x'),
                                                  "1.5",
                                                  "-0.0",
                                                  "6.5",
                                                  "4",
                                                  "20",
                                                  "24",
                                                  "100",
                                                  "\"1, 2\"",
                                                  "[1, 2, 3]",
                                                  "{a: 1}"};
  return values;
}

// The template `node` (yaml-cpp's, alias-free) as a Tree; false when it is
// deeper than `depth` (templates come from the seeds, which are small).
bool ToTree(const YAML::Node& node, Tree* out, int depth) {
  if (depth > 64) return false;
  switch (node.Type()) {
    case YAML::NodeType::Sequence:
      out->kind = Tree::kSequence;
      out->flow = node.Style() == YAML::EmitterStyle::Flow;
      for (const YAML::Node& item : node) {
        out->items.emplace_back();
        if (!ToTree(item, &out->items.back(), depth + 1)) return false;
      }
      return true;
    case YAML::NodeType::Map:
      out->kind = Tree::kMap;
      out->flow = node.Style() == YAML::EmitterStyle::Flow;
      for (const auto& entry : node) {
        out->items.emplace_back();
        if (!ToTree(entry.first, &out->items.back(), depth + 1)) return false;
        out->items.emplace_back();
        if (!ToTree(entry.second, &out->items.back(), depth + 1)) return false;
      }
      return true;
    case YAML::NodeType::Scalar:
      out->text = node.Scalar();
      return true;
    default:
      out->text = "~";
      return true;
  }
}

// A scalar (keys from `keys` when `key`).
std::string ScalarFrom(FuzzInput& in, const std::vector<std::string>& keys, bool key) {
  if (key && !keys.empty() && in.Below(4) != 0) return in.Pick(keys);
  switch (in.Below(4)) {
    case 0:
      return in.Pick(HostileScalars());
    case 1:
      return std::to_string(static_cast<std::int64_t>(in.Bits(8)));
    case 2:
      return keys.empty() ? "k" : in.Pick(keys);
    default: {
      std::string text = in.Bytes(24);
      return text.empty() ? "v" : text;
    }
  }
}

// A tree made from nothing, at most `depth` levels more.
Tree Generate(FuzzInput& in, const std::vector<std::string>& keys, int depth) {
  Tree t;
  const std::uint32_t kind = depth > 0 ? in.Below(3) : 0;
  if (kind == 0) {
    t.text = ScalarFrom(in, keys, false);
    return t;
  }
  t.kind = kind == 1 ? Tree::kSequence : Tree::kMap;
  t.flow = in.Flip();
  const std::uint32_t n = in.Below(5);
  for (std::uint32_t i = 0; i < n && in.more(); ++i) {
    if (t.kind == Tree::kMap) {
      Tree k;
      k.text = ScalarFrom(in, keys, true);
      t.items.push_back(std::move(k));
    }
    t.items.push_back(Generate(in, keys, depth - 1));
  }
  return t;
}

// Nodes of `t`, counting stops at `cap`.
int NodeCount(const Tree& t, int cap) {
  int n = 1;
  for (const Tree& child : t.items) {
    if (n >= cap) break;
    n += NodeCount(child, cap - n);
  }
  return n;
}

// State of one mutation walk: anchors named so far (ancestors' included,
// which is what makes `&a [*a]`).
struct Walk {
  FuzzInput& in;
  const std::vector<std::string>& keys;
  std::vector<std::string> anchors;
  int nodes = 0;
};

// Mutates `t` in place as the recipe says, then its children.
void Mutate(Walk& w, Tree& t, int depth) {
  if (++w.nodes > 4000 || depth > 80) return;
  const std::uint8_t op = w.in.Byte();
  // Most bytes keep the node; the rest pick one change (0 = keep, so an
  // exhausted recipe leaves the template as it is).
  switch (op < 192 ? 0 : op % 10) {
    case 1:  // another value
      if (t.kind == Tree::kScalar) t.text = ScalarFrom(w.in, w.keys, false);
      break;
    case 2:  // an anchor on this node
      t.anchor = "a" + std::to_string(w.anchors.size());
      w.anchors.push_back(t.anchor);
      break;
    case 3:  // an alias to an anchor named so far (an ancestor's too)
      if (!w.anchors.empty()) {
        t = Tree{};
        t.kind = Tree::kAlias;
        t.text = w.in.Pick(w.anchors);
        return;
      }
      break;
    case 4: {  // nested deeper: k levels of one-item sequences or maps
      const int levels = 1 + static_cast<int>(w.in.Below(40));
      for (int i = 0; i < levels; ++i) {
        Tree outer;
        outer.kind = w.in.Flip() ? Tree::kSequence : Tree::kMap;
        outer.flow = w.in.Flip();
        if (outer.kind == Tree::kMap) {
          Tree k;
          k.text = ScalarFrom(w.in, w.keys, true);
          outer.items.push_back(std::move(k));
        }
        outer.items.push_back(std::move(t));
        t = std::move(outer);
      }
      break;
    }
    case 5:  // replaced by a tree made from nothing
      t = Generate(w.in, w.keys, 1 + static_cast<int>(w.in.Below(6)));
      break;
    case 6:  // flow or block
      t.flow = !t.flow;
      break;
    case 7:  // a child removed
      if (t.kind == Tree::kSequence && !t.items.empty()) {
        t.items.erase(t.items.begin() + w.in.Below(static_cast<std::uint32_t>(t.items.size())));
      } else if (t.kind == Tree::kMap && t.items.size() >= 2) {
        const std::size_t at = 2 * w.in.Below(static_cast<std::uint32_t>(t.items.size() / 2));
        t.items.erase(t.items.begin() + static_cast<std::ptrdiff_t>(at),
                      t.items.begin() + static_cast<std::ptrdiff_t>(at) + 2);
      }
      break;
    case 8:  // a small child repeated (a duplicate key in a map)
      if (!t.items.empty() && NodeCount(t, 64) < 64) {
        const std::size_t step = t.kind == Tree::kMap ? 2 : 1;
        const std::size_t at = step * w.in.Below(static_cast<std::uint32_t>(t.items.size() / step));
        std::vector<Tree> copy(t.items.begin() + static_cast<std::ptrdiff_t>(at),
                               t.items.begin() + static_cast<std::ptrdiff_t>(at + step));
        const std::uint32_t times = 1 + w.in.Below(8);
        for (std::uint32_t i = 0; i < times; ++i)
          t.items.insert(t.items.end(), copy.begin(), copy.end());
      }
      break;
    case 9:  // a child added
      if (t.kind == Tree::kMap) {
        Tree k;
        k.text = ScalarFrom(w.in, w.keys, true);
        t.items.push_back(std::move(k));
        t.items.push_back(Generate(w.in, w.keys, 2));
      } else if (t.kind == Tree::kSequence) {
        t.items.push_back(Generate(w.in, w.keys, 2));
      }
      break;
    default:
      break;
  }
  for (Tree& child : t.items) Mutate(w, child, depth + 1);
}

// `text` as a YAML scalar: plain where that reads back as itself, else
// double-quoted with escapes. Texts from HostileScalars that carry their
// own syntax (tags, quotes, flow) are written as they are.
std::string ScalarText(const std::string& text) {
  if (text.empty()) return "\"\"";
  const char first = text.front();
  if (first == '!' || first == '"' || first == '\'' || first == '[' || first == '{' || first == '~')
    return text;
  bool plain = true;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7f || c == ':' || c == '#' || c == ',' || c == '[' || c == ']' ||
        c == '{' || c == '}' || c == '&' || c == '*' || c == '"' || c == '\'' || c == '|' ||
        c == '>' || c == '%' || c == '@' || c == '`')
      plain = false;
  }
  const bool dash_ok = first != '-' || (text.size() > 1 && text[1] != ' ');
  if (plain && dash_ok && first != '?' && first != ' ' && text.back() != ' ') return text;
  std::string out = "\"";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u >= 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", u);
      out += hex;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// Appends `t` in flow style.
void EmitFlow(const Tree& t, std::string* out) {
  if (!t.anchor.empty()) *out += "&" + t.anchor + " ";
  switch (t.kind) {
    case Tree::kAlias:
      *out += "*" + t.text;
      return;
    case Tree::kScalar:
      *out += ScalarText(t.text);
      return;
    case Tree::kSequence:
      *out += "[";
      for (std::size_t i = 0; i < t.items.size(); ++i) {
        if (i) *out += ", ";
        EmitFlow(t.items[i], out);
      }
      *out += "]";
      return;
    case Tree::kMap:
      *out += "{";
      for (std::size_t i = 0; i + 1 < t.items.size(); i += 2) {
        if (i) *out += ", ";
        EmitFlow(t.items[i], out);
        *out += ": ";
        EmitFlow(t.items[i + 1], out);
      }
      *out += "}";
      return;
  }
}

bool IsEmptyCollection(const Tree& t) {
  return (t.kind == Tree::kSequence || t.kind == Tree::kMap) && t.items.empty();
}

// Appends `t` as a block node whose lines are indented by `indent` spaces;
// the caller wrote what comes before it on the current line ("key:" or "-").
void EmitBlock(const Tree& t, int indent, std::string* out) {
  const bool block =
      !t.flow && !IsEmptyCollection(t) && (t.kind == Tree::kSequence || t.kind == Tree::kMap);
  if (!block) {
    *out += " ";
    EmitFlow(t, out);
    *out += "\n";
    return;
  }
  if (!t.anchor.empty()) *out += " &" + t.anchor;
  *out += "\n";
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  if (t.kind == Tree::kSequence) {
    for (const Tree& item : t.items) {
      *out += pad + "-";
      EmitBlock(item, indent + 2, out);
    }
    return;
  }
  for (std::size_t i = 0; i + 1 < t.items.size(); i += 2) {
    const Tree& key = t.items[i];
    *out += pad;
    if (key.kind == Tree::kSequence || key.kind == Tree::kMap || !key.anchor.empty())
      *out += "? ";  // complex keys written explicitly, on one line
    EmitFlow(key, out);
    if (key.kind == Tree::kSequence || key.kind == Tree::kMap || !key.anchor.empty())
      *out += "\n" + pad;
    *out += ":";
    EmitBlock(t.items[i + 1], indent + 2, out);
  }
}

// ------------------------------------------------------------------ PNG, zlib

std::uint32_t Crc(const std::string& bytes) {
  return static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

void PutBe32(std::string* out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out->push_back(static_cast<char>(v >> shift));
}

// A chunk: length, type, data, CRC (wrong when `bad_crc`).
void Chunk(std::string* out, const char* type, const std::string& data, bool bad_crc = false) {
  PutBe32(out, static_cast<std::uint32_t>(data.size()));
  const std::string body = std::string(type, 4) + data;
  *out += body;
  PutBe32(out, Crc(body) ^ (bad_crc ? 0x1u : 0u));
}

std::string Compress(const std::string& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string out(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(out.data()), &size,
                reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()),
                Z_BEST_SPEED) != Z_OK)
    return {};
  out.resize(size);
  return out;
}

// `value` as an integer, clamped to int64's range (NaN as 0): no cast of a
// double the target type cannot hold.
std::int64_t Clamped(double value) {
  if (!(value == value)) return 0;
  if (value >= 9.2e18) return std::numeric_limits<std::int64_t>::max();
  if (value <= -9.2e18) return std::numeric_limits<std::int64_t>::min();
  return static_cast<std::int64_t>(value);
}

// ------------------------------------------------------------------ numbers as text

std::string HostileNumber(FuzzInput& in) {
  switch (in.Below(6)) {
    case 0:
      return std::string(
          in.Pick({"nan", "inf", "-inf", "1e309", "-1e309", "1e-320", "-0", "0x10", "1e", "--1",
                   "+5", "4294967296", "-2147483649", "99999999999999999999", ".", ""}));
    case 1:
      return std::to_string(static_cast<std::int64_t>(in.Bits(8)));
    case 2:
      return std::to_string(static_cast<std::int32_t>(in.Bits(4)));
    default:
      return std::to_string(static_cast<int>(in.Below(200)) - 100) + "." +
             std::to_string(in.Below(1000));
  }
}

}  // namespace

std::string YamlFrom(FuzzInput& in, const std::vector<std::string>& templates,
                     const std::vector<std::string>& keys) {
  Tree root;
  bool from_template = false;
  if (!templates.empty()) {
    const std::string& text = templates[in.Below(static_cast<std::uint32_t>(templates.size()))];
    try {
      from_template = ToTree(YAML::Load(text), &root, 0);
    } catch (const YAML::Exception&) {
      from_template = false;
    }
  }
  if (!from_template) root = Generate(in, keys, 1 + static_cast<int>(in.Below(8)));
  Walk walk{in, keys, {}, 0};
  Mutate(walk, root, 0);
  std::string out;
  const bool directive = in.Below(8) == 1;
  if (directive) out += "%YAML 1.2\n---\n";
  if (root.flow || root.kind == Tree::kScalar || root.kind == Tree::kAlias ||
      IsEmptyCollection(root)) {
    EmitFlow(root, &out);
    out += "\n";
  } else if (root.kind == Tree::kMap && root.anchor.empty()) {
    std::string body;
    EmitBlock(root, 0, &body);
    out += body.substr(1);  // no line break before the first key
  } else {
    if (!directive) out += "---";
    EmitBlock(root, 0, &out);
  }
  // Sometimes a second document, or bytes of the recipe after the end.
  if (in.Below(8) == 2) out += "---\n" + ScalarText(ScalarFrom(in, keys, false)) + "\n";
  if (in.Below(16) == 3) out += in.Bytes(32);
  return out;
}

std::string PlyFrom(FuzzInput& in) {
  struct Prop {
    std::string name, type, count_type;
    bool list = false;
  };
  struct Elem {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Prop> props;
  };
  static const std::vector<std::string> types = {
      "float", "double", "uchar", "char",   "short", "ushort", "int",     "uint",
      "int8",  "uint8",  "int16", "uint16", "int32", "uint32", "float32", "float64"};
  static const std::vector<std::string> vertex_names = {
      "x", "y", "z", "nx", "ny", "nz", "uncertainty_mm", "line", "flags", "red", "s"};
  static const std::vector<std::string> element_names = {"vertex",   "face",   "junk", "edge",
                                                         "material", "vertex", "face"};
  const int format = static_cast<int>(in.Below(4));  // 3: something else
  std::string out = "ply\n";
  out += format == 0   ? "format binary_little_endian 1.0\n"
         : format == 1 ? "format ascii 1.0\n"
         : format == 2 ? "format binary_big_endian 1.0\n"
                       : std::string(in.Pick(
                             {"format ascii 2.0\n", "format binary 1.0\n", "format ascii\n", ""}));
  if (in.Below(4) == 1) out += "comment made by the fuzzer\nobj_info x\n";
  std::vector<Elem> elements;
  const std::uint32_t n_elements = 1 + in.Below(4);
  for (std::uint32_t e = 0; e < n_elements; ++e) {
    Elem el;
    el.name = e == 0 ? "vertex" : in.Pick(element_names);
    switch (in.Below(8)) {
      case 0:
        el.count = in.Below(8);
        break;
      case 1:  // counts the body cannot hold, 2^64 - 1 among them
        el.count = in.Pick(std::vector<std::uint64_t>{
            std::numeric_limits<std::uint64_t>::max(), std::uint64_t{1} << 32,
            (std::uint64_t{1} << 31) - 1, 1000000, std::uint64_t{1} << 62});
        break;
      case 2:
        el.count = in.Bits(8);
        break;
      default:
        el.count = in.Below(40);
    }
    const bool is_vertex = el.name == "vertex";
    const std::uint32_t n_props =
        is_vertex ? 3 + in.Below(6) : (el.name == "face" ? 1 + in.Below(2) : in.Below(4));
    for (std::uint32_t p = 0; p < n_props; ++p) {
      Prop prop;
      if (el.name == "face" && p == 0) {
        prop = {in.Pick({"vertex_indices", "vertex_index", "indices"}).data(), in.Pick(types),
                in.Pick(std::vector<std::string>{"uchar", "uint", "int", "ushort", "float"}), true};
      } else if (is_vertex && p < 3) {
        prop = {std::string(1, static_cast<char>('x' + p)),
                in.Below(4) == 0 ? in.Pick(types) : "float", "", false};
      } else if (in.Below(4) == 0) {
        prop = {"l" + std::to_string(p), in.Pick(types), in.Pick(types), true};
      } else {
        prop = {is_vertex ? in.Pick(vertex_names) : "p" + std::to_string(p), in.Pick(types), "",
                false};
      }
      el.props.push_back(prop);
    }
    elements.push_back(el);
    out += "element " + el.name + " " + std::to_string(el.count) + "\n";
    for (const Prop& p : el.props)
      out += p.list ? "property list " + p.count_type + " " + p.type + " " + p.name + "\n"
                    : "property " + p.type + " " + p.name + "\n";
  }
  if (in.Below(16) == 1)
    out += std::string(
        in.Pick({"property float lost\n", "element\n", "bogus line\n", "element a -1\n"}));
  out += "end_header\n";
  // The body: values of the declared types, at most 48 items an element.
  const bool ascii = format == 1;
  const bool big = format == 2;
  auto put = [&](const std::string& type, double value) {
    if (ascii) {
      out += (value == static_cast<double>(Clamped(value)) ? std::to_string(Clamped(value))
                                                           : std::to_string(value)) +
             " ";
      return;
    }
    std::string bytes;
    auto raw = [&](const void* p, std::size_t n) {
      bytes.assign(static_cast<const char*>(p), n);
      if (big) bytes.assign(bytes.rbegin(), bytes.rend());
    };
    if (type == "float" || type == "float32") {
      const float f = std::isfinite(value) && std::abs(value) >= 3e38
                          ? std::copysign(3e38f, static_cast<float>(value > 0 ? 1 : -1))
                          : static_cast<float>(value);
      raw(&f, 4);
    } else if (type == "double" || type == "float64") {
      raw(&value, 8);
    } else if (type == "short" || type == "int16" || type == "ushort" || type == "uint16") {
      const auto v = static_cast<std::int16_t>(Clamped(value));
      raw(&v, 2);
    } else if (type == "int" || type == "int32" || type == "uint" || type == "uint32") {
      const auto v = static_cast<std::int32_t>(Clamped(value));
      raw(&v, 4);
    } else {
      const auto v = static_cast<std::int8_t>(Clamped(value));
      raw(&v, 1);
    }
    out += bytes;
  };
  auto value = [&]() -> double {
    switch (in.Below(8)) {
      case 0:
        return in.Pick(std::vector<double>{std::numeric_limits<double>::quiet_NaN(),
                                           std::numeric_limits<double>::infinity(), -1.0, 1e30,
                                           -2147483648.0, 4294967295.0, 255.0});
      case 1:
        return static_cast<double>(in.Below(256));
      default:
        return static_cast<double>(static_cast<int>(in.Below(64)) - 8);
    }
  };
  for (const Elem& el : elements) {
    const std::uint64_t items = std::min<std::uint64_t>(el.count, 48);
    for (std::uint64_t i = 0; i < items && in.more(); ++i) {
      for (const Prop& p : el.props) {
        if (p.list) {
          const std::uint32_t n = in.Below(8) == 0 ? in.Below(256) : 3 + in.Below(3);
          put(p.count_type, n);
          for (std::uint32_t k = 0; k < std::min<std::uint32_t>(n, 16); ++k)
            put(p.type, in.Below(4) == 0 ? value() : static_cast<double>(in.Below(8)));
        } else {
          put(p.type, value());
        }
      }
      if (ascii) out += "\n";
    }
  }
  switch (in.Below(8)) {
    case 1:  // cut short
      out.resize(out.size() - std::min<std::size_t>(out.size(), in.Below(64)));
      break;
    case 2:  // junk after the end
      out += in.Bytes(64);
      break;
    default:
      break;
  }
  return out;
}

std::string ObjFrom(FuzzInput& in) {
  std::string out;
  int vertices = 0;
  const std::uint32_t lines = 4 + in.Below(60);
  for (std::uint32_t i = 0; i < lines && (i < 4 || in.more()); ++i) {
    switch (in.Below(10)) {
      case 0:
      case 1:
      case 2:
      case 3: {
        out += "v";
        const std::uint32_t n = in.Below(8) == 0 ? in.Below(7) : 3;
        for (std::uint32_t k = 0; k < n; ++k)
          out += " " + (in.Below(6) == 0 ? HostileNumber(in) : std::to_string(in.Below(100)));
        out += "\n";
        ++vertices;
        break;
      }
      case 4:
      case 5:
      case 6: {
        out += "f";
        const std::uint32_t n = in.Below(8) == 0 ? in.Below(12) : 3 + in.Below(2);
        for (std::uint32_t k = 0; k < n; ++k) {
          std::string ref;
          switch (in.Below(8)) {
            case 0:
              ref = HostileNumber(in);
              break;
            case 1:
              ref = "-" + std::to_string(1 + in.Below(static_cast<std::uint32_t>(vertices + 2)));
              break;
            default:
              ref = std::to_string(1 + in.Below(static_cast<std::uint32_t>(vertices + 2)));
          }
          out += " " + ref + std::string(in.Pick({"", "", "/1", "//1", "/1/1", "/", "//", "/x"}));
        }
        out += "\n";
        break;
      }
      case 7:
        out += std::string(
            in.Pick({"vn 0 0 1\n", "vt 0.5 0.5\n", "# comment\n", "\n", "o face\n", "g group\n",
                     "s off\n", "usemtl m\n", "mtllib x.mtl\n", "   \t\n", "f\n", "v\n"}));
        break;
      case 8:
        out += in.Bytes(24) + "\n";
        break;
      default:
        out += "v " + std::to_string(in.Below(50)) + " " + std::to_string(in.Below(50)) + " 0\n";
        ++vertices;
    }
  }
  return out;
}

std::string PngFrom(FuzzInput& in) {
  if (in.Below(8) == 7) {  // now and then a PNM, the other format frames come in
    std::string pnm = std::string(in.Pick({"P5", "P2", "P6", "P3", "P5"})) + "\n";
    if (in.Flip()) pnm += "# comment\n";
    pnm += std::to_string(in.Below(8) == 0 ? in.Bits(4) : 16 + in.Below(49)) + " " +
           std::to_string(in.Below(8) == 0 ? in.Bits(4) : 16 + in.Below(49)) + "\n" +
           std::string(in.Pick({"255", "65535", "0", "1", "70000"})) + "\n";
    return pnm + in.Rest();
  }
  auto side = [&]() -> std::uint32_t {
    switch (in.Below(8)) {
      case 0:  // at and around every limit, and far beyond
        return in.Pick(std::vector<std::uint32_t>{0, 1, 15, 16, 17, 4096, 4097, 16384, 16385,
                                                  100000, 0x7fffffffu, 0x80000000u, 0xffffffffu});
      case 1:
        return static_cast<std::uint32_t>(in.Bits(4));
      default:
        return 16 + in.Below(49);
    }
  };
  const std::uint32_t width = side();
  const std::uint32_t height = side();
  struct Mode {
    std::uint8_t colour, depth, channels;
  };
  static const std::vector<Mode> modes = {{0, 8, 1},  {0, 16, 1}, {0, 1, 1},  {0, 2, 1}, {0, 4, 1},
                                          {2, 8, 3},  {2, 16, 3}, {3, 8, 1},  {3, 4, 1}, {4, 8, 2},
                                          {4, 16, 2}, {6, 8, 4},  {6, 16, 4}, {5, 8, 1}, {2, 3, 3}};
  const Mode mode = in.Pick(modes);
  const bool interlaced = in.Below(8) == 1;
  std::string out("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  PutBe32(&ihdr, width);
  PutBe32(&ihdr, height);
  ihdr += static_cast<char>(mode.depth);
  ihdr += static_cast<char>(mode.colour);
  ihdr += static_cast<char>(in.Below(16) == 1 ? 1 : 0);  // compression
  ihdr += static_cast<char>(in.Below(16) == 1 ? 1 : 0);  // filter method
  ihdr += static_cast<char>(interlaced ? 1 : 0);
  Chunk(&out, "IHDR", ihdr, in.Below(16) == 1);
  if (mode.colour == 3 || in.Below(16) == 1) {
    const std::uint32_t entries = in.Below(8) == 0 ? in.Below(300) : 1 + in.Below(16);
    std::string plte;
    for (std::uint32_t i = 0; i < entries * 3; ++i) plte += static_cast<char>(in.Byte());
    Chunk(&out, "PLTE", plte);
    if (in.Below(4) == 1) Chunk(&out, "tRNS", in.Bytes(16));
  }
  if (in.Below(8) == 1) Chunk(&out, "gAMA", std::string("\0\0\xb1\x8f", 4));
  // Scan lines for the rows the file claims, at most 64 of at most 4 KiB.
  const std::uint64_t bits_per_row = std::uint64_t{width} * mode.depth * mode.channels;
  const std::uint64_t row_bytes = (bits_per_row + 7) / 8;
  std::string raw;
  if (row_bytes <= 4096) {
    const std::uint32_t rows = std::min<std::uint32_t>(height, 64);
    for (std::uint32_t y = 0; y < rows; ++y) {
      raw += static_cast<char>(in.Below(8) == 0 ? in.Below(7) : 0);  // filter byte (5, 6 bad)
      for (std::uint64_t x = 0; x < row_bytes; ++x)
        raw += static_cast<char>(in.more() ? in.Byte() : static_cast<std::uint8_t>(x * 7 + y));
    }
  } else {
    raw = in.Bytes(200);
  }
  std::string idat = Compress(raw);
  if (in.Below(8) == 1) idat.resize(idat.size() / 2);  // cut short
  if (in.Below(4) == 1 && idat.size() > 2) {           // in two chunks
    const std::size_t half = idat.size() / 2;
    Chunk(&out, "IDAT", idat.substr(0, half));
    Chunk(&out, "IDAT", idat.substr(half));
  } else {
    Chunk(&out, "IDAT", idat, in.Below(32) == 1);
  }
  if (in.Below(8) != 1) Chunk(&out, "IEND", "");
  return out;
}

std::string JsonFrom(FuzzInput& in) {
  static const std::vector<std::string> keys = {
      "junctions", "lines", "p", "q", "v", "x", "y", "points", "samples", "value", "uncertainty"};
  std::string out;
  std::vector<char> open;  // ']' or '}' to close, innermost last
  std::vector<bool> first;
  const std::uint32_t steps = 1 + in.Below(2000);
  auto value_start = [&] {
    if (!open.empty()) {
      if (!first.back()) out += ",";
      first.back() = false;
      if (open.back() == '}') out += "\"" + in.Pick(keys) + "\":";
    }
  };
  for (std::uint32_t i = 0; i < steps && (i == 0 || in.more() || !open.empty()); ++i) {
    const std::uint32_t op = in.more() ? in.Below(8) : 7;  // an exhausted recipe closes
    if (op <= 1 && open.size() < 100000) {
      value_start();
      out += op == 0 ? "[" : "{";
      open.push_back(op == 0 ? ']' : '}');
      first.push_back(true);
      // A run of openings now and then: deep nesting from a few bytes.
      if (in.Below(16) == 1) {
        const std::uint32_t run = in.Below(65536);
        for (std::uint32_t k = 0; k < run; ++k) {
          out += "[";
          open.push_back(']');
          first.push_back(false);
        }
      }
    } else if (op <= 5 || open.empty()) {
      value_start();
      switch (in.Below(6)) {
        case 0:
          out += HostileNumber(in);
          break;
        case 1:
          out += std::string(in.Pick(
              {"true", "false", "null", "\"\\ud800\"", "\"\\u0000\"", "1e400", "-0", "\"x\""}));
          break;
        default:
          out += std::to_string(in.Below(1000));
      }
      if (open.empty()) break;
    } else {
      out += open.back();
      open.pop_back();
      first.pop_back();
      if (open.empty()) break;
    }
  }
  if (in.Below(8) == 1) out += in.Bytes(16);
  return out;
}

}  // namespace bsls::fuzz
