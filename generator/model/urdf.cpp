// URDF -> Model.
//
// Two XML parsers read every URDF: tinyxml2 here (well-formedness, the line of
// every <link> and <joint> for messages, early limits) and TinyXML inside
// urdfdom, whose result is the model. They read some documents differently: a
// processing instruction `<?pi > <robot>...</robot> ?>` ends at the first '>'
// for TinyXML and at '?>' for tinyxml2, so a robot inside it is invisible to
// one and the model of the other; without an XML declaration TinyXML cuts a
// character reference above U+00FF to its low byte, so names tinyxml2 reads
// as distinct collapse into one. The bounds must hold for what is built, so
// proxgen does both of:
//  1. scanMarkup(), before either parser, refuses what the two would read
//     differently: any processing instruction but a leading <?xml ...?> that
//     ends at its first '>', <!DOCTYPE>/<!ENTITY>/<![CDATA[ (any `<!` but a
//     comment), character references outside ASCII, a bare '&', NUL bytes,
//     bytes that are not UTF-8 (TinyXML reads them by its own tables). In
//     what is left both parsers see the same elements, so the nesting and
//     attribute bounds it checks (and tinyxml2's) bound TinyXML's recursion and
//     its DOM too.
//  2. Every limit on the tree (links, joints, depth, one parent per link, no
//     cycle, valid UTF-8 names) is checked again on urdfdom's ModelInterface,
//     the thing the model is built from, before the builder walks it. The same
//     checks on tinyxml2's view run first, to refuse before urdfdom builds its
//     copy (and to name a joint where urdfdom only says "no root link").
// The builder then walks the tree without recursion, merges fixed joints and
// validates every number that will reach a solver.
#include "model/urdf.hpp"

#include <console_bridge/console.h>
#include <fmt/format.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <vector>

#include "model/error.hpp"
#include "model/input.hpp"
#include "model/warn.hpp"

namespace proxgen {
namespace {

// Collects what urdfdom reports through console_bridge instead of letting it
// print to the terminal; its errors become our message. urdfdom logs some
// errors (an <inertial> number that is not a double) and still returns a
// model with zeros in their place, so any logged error is fatal. urdfdom
// quotes names and values raw, hence oneLine().
class Capture : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_ERROR || count++ >= 3) return;
    errors += (errors.empty() ? "" : "; ") + oneLine(text);
  }
  std::string errors;  // the first three, joined
  int count = 0;
};

std::mutex g_urdfdomMutex;  // console_bridge's handler is process-global

struct LineIndex {
  std::map<std::string, int> link, joint;
};

// One <joint>'s place in the tree, as one of the parsers read it.
struct Edge {
  std::string joint, parent, child;
};

// The line of byte `pos` (1-based), counted only when a message needs it.
int lineAt(const std::string& text, std::size_t pos) {
  return 1 + int(std::count(text.begin(), text.begin() + std::ptrdiff_t(std::min(pos, text.size())), '\n'));
}

bool startsWith(const std::string& s, std::size_t at, const char* prefix) {
  return s.compare(at, std::strlen(prefix), prefix) == 0;
}

// Point 1 of the file comment: one linear pass over the text, before either
// XML parser. It follows the syntax both parsers share (elements, quoted
// attributes, comments, text, entities) and refuses the rest, with the line.
void scanMarkup(const std::string& xml, const std::string& path) {
  const std::size_t n = xml.size();
  const auto failAt = [&](std::size_t pos, const std::string& what) {
    fail(fmt::format("{}:{}", path, lineAt(xml, pos)), "", what);
  };
  // The whole text is UTF-8, so every name is (names reach JSON output).
  if (std::size_t bad = 0; !isValidUtf8(xml, &bad))
    failAt(bad, fmt::format("is not valid UTF-8 (byte 0x{:02x} at offset {}): a URDF is UTF-8 text, and names reach "
                            "JSON output",
                            static_cast<unsigned char>(xml[bad]), bad));
  const auto malformed = [&](std::size_t pos, const char* what) {
    failAt(pos, fmt::format("not well-formed XML ({})", what));
  };
  const auto isSpace = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  // '&' must start one of the five predefined entities or a character
  // reference to an ASCII character (1 to 127), which both parsers decode to
  // the same byte; returns the position after it.
  const auto entity = [&](std::size_t k) {
    for (const char* e : {"&lt;", "&gt;", "&amp;", "&quot;", "&apos;"})
      if (startsWith(xml, k, e)) return k + std::strlen(e);
    if (!startsWith(xml, k, "&#")) failAt(k, "a bare '&' (write &amp;): not well-formed XML");
    const bool hex = k + 2 < n && xml[k + 2] == 'x';
    std::size_t j = k + (hex ? 3 : 2);
    const std::size_t first = j;
    unsigned long value = 0;
    while (j < n && j - first < 8 && (hex ? std::isxdigit(static_cast<unsigned char>(xml[j])) : std::isdigit(static_cast<unsigned char>(xml[j])))) {
      const char c = xml[j++];
      value = value * (hex ? 16 : 10) + unsigned(std::isdigit(static_cast<unsigned char>(c)) ? c - '0' : std::tolower(c) - 'a' + 10);
    }
    if (j == first || j >= n || xml[j] != ';') failAt(k, "a malformed character reference (expected &#NNN; or &#xHH;)");
    if (value == 0 || value > 0x7f)
      failAt(k, fmt::format("the character reference {} is not an ASCII character: write the character itself (in "
                            "UTF-8); TinyXML, inside urdfdom, and tinyxml2 decode it differently",
                            xml.substr(k, j + 1 - k)));
    return j + 1;
  };
  std::size_t depth = 0, attributes = 0;
  bool content = false;  // anything but white space seen: no XML declaration after it
  std::size_t k = startsWith(xml, 0, "\xEF\xBB\xBF") ? 3 : 0;  // a UTF-8 byte-order mark
  while (k < n) {
    const char c = xml[k];
    if (c == '\0') failAt(k, "holds a NUL byte, which XML does not allow (and urdfdom would stop reading at)");
    if (c == '&') {
      k = entity(k);
      content = true;
      continue;
    }
    if (c != '<') {
      content = content || !isSpace(c);
      ++k;
      continue;
    }
    if (startsWith(xml, k, "<!--")) {
      const std::size_t e = xml.find("-->", k + 4);
      if (e == std::string::npos) malformed(k, "an unterminated comment");
      k = e + 3;
      content = true;
      continue;
    }
    if (startsWith(xml, k, "<?")) {
      // Only the XML declaration, first, closed by its first '>': TinyXML ends
      // it there, tinyxml2 at "?>".
      const std::size_t e = xml.find('>', k);
      if (content || !startsWith(xml, k, "<?xml") || k + 5 >= n || !isSpace(xml[k + 5]))
        failAt(k, "a processing instruction (<?...?>): refused, because the two XML parsers proxgen and urdfdom use "
                  "read them differently; only a leading <?xml ...?> declaration is accepted");
      if (e == std::string::npos || xml[e - 1] != '?' || xml.find('<', k + 1) < e)
        failAt(k, "the XML declaration must end with '?>' at its first '>' (the two XML parsers proxgen and urdfdom use "
                  "end it at different places otherwise)");
      k = e + 1;
      content = true;
      continue;
    }
    if (startsWith(xml, k, "<!"))
      failAt(k, "<!DOCTYPE>, <!ENTITY> and <![CDATA[ are refused: the two XML parsers proxgen and urdfdom use read "
                "them differently, and a URDF needs none of them");
    content = true;
    if (startsWith(xml, k, "</")) {
      if (depth == 0) malformed(k, "an end tag without a start tag");
      const std::size_t e = xml.find('>', k);
      if (e == std::string::npos) malformed(k, "an unterminated end tag");
      --depth;
      k = e + 1;
      continue;
    }
    // A start tag: the name, then quoted attributes, then '>' or '/>'.
    const std::size_t tag = k++;
    const std::size_t nameStart = k;
    while (k < n && !isSpace(xml[k]) && xml[k] != '/' && xml[k] != '>' && xml[k] != '<') ++k;
    if (k == nameStart) malformed(tag, "a '<' that starts no tag");
    if (depth + 1 > kMaxXmlDepth)
      failAt(tag, fmt::format("elements nested more than {} deep: proxgen reads XML at most {} levels deep", kMaxXmlDepth,
                              kMaxXmlDepth));
    std::size_t onElement = 0;
    for (;;) {
      while (k < n && isSpace(xml[k])) ++k;
      if (k >= n) malformed(tag, "an unterminated tag");
      if (xml[k] == '>') {
        ++depth;
        ++k;
        break;
      }
      if (xml[k] == '/') {
        if (k + 1 >= n || xml[k + 1] != '>') malformed(k, "a '/' inside a tag");
        k += 2;
        break;
      }
      const std::size_t attribute = k;
      while (k < n && !isSpace(xml[k]) && xml[k] != '=' && xml[k] != '>' && xml[k] != '/' && xml[k] != '<') ++k;
      if (k == attribute) malformed(k, "a malformed attribute");
      while (k < n && isSpace(xml[k])) ++k;
      if (k >= n || xml[k] != '=') malformed(attribute, "an attribute without '=' and a quoted value");
      ++k;
      while (k < n && isSpace(xml[k])) ++k;
      if (k >= n || (xml[k] != '"' && xml[k] != '\'')) malformed(attribute, "an attribute value without quotes");
      const char quote = xml[k++];
      while (k < n && xml[k] != quote) {
        if (xml[k] == '<') malformed(k, "a '<' inside an attribute value (write &lt;)");
        if (xml[k] == '\0') failAt(k, "holds a NUL byte, which XML does not allow (and urdfdom would stop reading at)");
        k = xml[k] == '&' ? entity(k) : k + 1;
      }
      if (k >= n) malformed(attribute, "an unterminated attribute value");
      ++k;
      if (++onElement > kMaxXmlAttributesPerElement)
        failAt(tag, fmt::format("an element with more than {} attributes: proxgen reads at most {} per element",
                                kMaxXmlAttributesPerElement, kMaxXmlAttributesPerElement));
      if (++attributes > kMaxUrdfAttributes)
        failAt(tag, fmt::format("more than {} attributes: proxgen reads URDFs of at most {} attributes", kMaxUrdfAttributes,
                                kMaxUrdfAttributes));
    }
  }
}

// The tree checks, on one parser's reading of the joints (the same function
// for tinyxml2's view and for urdfdom's model, point 2 of the file comment).
// A link is the child of at most one joint, no joint closes a cycle, and no
// link is more than kMaxTreeDepth joints below its root. Linear in the number
// of joints: each link's depth is found once (a 50 MB chain).
void checkTreeShape(const std::vector<Edge>& edges, const LineIndex& index, const std::string& path) {
  const auto failAtJoint = [&](const std::string& joint, const std::string& what) {
    const auto line = index.joint.find(joint);
    fail(line == index.joint.end() ? path : fmt::format("{}:{}", path, line->second),
         fmt::format("joint {}", quoted(joint)), what);
  };
  std::map<std::string, const Edge*> parentOf;  // child link -> its joint
  for (const Edge& e : edges) {
    const auto [it, inserted] = parentOf.emplace(e.child, &e);
    if (!inserted)
      failAtJoint(e.joint, fmt::format("has child link {}, which is already the child of joint {}: a link hangs from "
                                       "one joint only (a URDF is a tree)",
                                       quoted(e.child), quoted(it->second->joint)));
    if (e.parent == e.child)
      failAtJoint(e.joint, fmt::format("has link {} as both parent and child: it closes a kinematic cycle (a URDF must "
                                       "be a tree)",
                                       quoted(e.child)));
  }
  std::map<std::string, std::size_t> depth;  // joints between a link and its root link
  std::vector<const Edge*> walk;
  for (const auto& start : parentOf) {
    // Up to a root or to a link whose depth is known. More steps up than there
    // are joints means the walk went round a cycle.
    walk.clear();
    std::string link = start.first;
    for (auto up = parentOf.find(link); up != parentOf.end() && !depth.count(link); up = parentOf.find(link)) {
      if (walk.size() > parentOf.size()) failAtJoint(up->second->joint, "closes a kinematic cycle: a URDF must be a tree");
      walk.push_back(up->second);
      link = up->second->parent;
    }
    std::size_t d = depth.count(link) ? depth.at(link) : 0;
    for (auto it = walk.rbegin(); it != walk.rend(); ++it) {
      depth[(*it)->child] = ++d;
      if (d > kMaxTreeDepth)
        failAtJoint((*it)->joint, fmt::format("is {} joints below the root link; proxgen reads trees at most {} joints deep",
                                              d, kMaxTreeDepth));
    }
  }
}

[[noreturn]] void tooMany(const std::string& where, const char* what) {
  fail(where, "",
       fmt::format("more than {} <{}> elements: proxgen reads robots of at most {} links", kMaxUrdfLinks, what, kMaxUrdfLinks));
}

// A xacro file (macros, properties, ${...} expressions, $(find ...)) is well-formed
// XML, and urdfdom would fail on it with a message about a number or a missing
// link that hides the cause: it must be expanded by xacro first. Refused at the
// first xacro element, or ${...} or $(...) in an attribute or a text, with the
// command to run. Not refused: comments (the "autogenerated by xacro" banner of
// every expanded file) and the xmlns:xacro declaration alone, which xacro before
// 1.13.3 (ROS Melodic) copied into every file it expanded (ros/xacro#144): such
// files are plain URDFs.
void refuseXacro(const tinyxml2::XMLDocument& doc, const std::string& path) {
  const auto refuse = [&](const tinyxml2::XMLElement* e, const std::string& element, const std::string& what) {
    // Where to write the expansion: robot.urdf.xacro -> robot.urdf, robot.xacro
    // -> robot.urdf, robot.urdf -> robot.expanded.urdf (never the input itself).
    const auto endsWith = [](const std::string& s, const std::string& tail) {
      return s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
    };
    std::string out = path;
    if (endsWith(out, ".xacro")) out.resize(out.size() - 6);
    else if (endsWith(out, ".urdf")) out.resize(out.size() - 5), out += ".expanded";
    if (!endsWith(out, ".urdf")) out += ".urdf";
    fail(fmt::format("{}:{}", path, e->GetLineNum()), element,
         fmt::format("{}: this is a xacro file, not a URDF: run xacro first (xacro {} > {})", what, path, out));
  };
  const auto isXacroText = [](const char* v) { return std::strstr(v, "${") || std::strstr(v, "$("); };
  // Depth first without recursion (the nesting is bounded, but a walk needs no stack).
  for (const tinyxml2::XMLElement* e = doc.FirstChildElement(); e;) {
    const std::string name = e->Name();
    if (name.rfind("xacro:", 0) == 0) refuse(e, fmt::format("element <{}>", oneLine(name, 80)), "a xacro element");
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      if (isXacroText(a->Value()))
        refuse(e, fmt::format("element <{}> attribute {}", oneLine(name, 80), quoted(a->Name())),
               fmt::format("{} is a xacro expression", quoted(a->Value())));
    }
    if (e->GetText() && isXacroText(e->GetText())) refuse(e, fmt::format("element <{}>", oneLine(name, 80)), "a xacro expression");
    if (e->FirstChildElement()) {
      e = e->FirstChildElement();
      continue;
    }
    while (e && !e->NextSiblingElement()) e = e->Parent() ? e->Parent()->ToElement() : nullptr;
    if (e) e = e->NextSiblingElement();
  }
}

LineIndex indexLines(const std::string& xml, const std::string& path) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
    fail(fmt::format("{}:{}", path, doc.ErrorLineNum()), "", fmt::format("not well-formed XML ({})", doc.ErrorName()));
  }
  refuseXacro(doc, path);
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) fail(path, "", "no <robot> element at the top level: not a URDF file");
  LineIndex index;
  std::vector<Edge> edges;
  std::size_t links = 0, joints = 0;
  for (auto* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    // Bounded before urdfdom builds its own copy and we build the model.
    links += std::string(e->Name()) == "link";
    joints += std::string(e->Name()) == "joint";
    if (links > kMaxUrdfLinks || joints > kMaxUrdfLinks) tooMany(fmt::format("{}:{}", path, e->GetLineNum()), e->Name());
    const char* name = e->Attribute("name");
    if (!name) continue;
    if (std::string(e->Name()) == "link") index.link.emplace(name, e->GetLineNum());
    if (std::string(e->Name()) != "joint") continue;
    index.joint.emplace(name, e->GetLineNum());
    const tinyxml2::XMLElement* parent = e->FirstChildElement("parent");
    const tinyxml2::XMLElement* child = e->FirstChildElement("child");
    if (parent && child && parent->Attribute("link") && child->Attribute("link"))
      edges.push_back({name, parent->Attribute("link"), child->Attribute("link")});
  }
  checkTreeShape(edges, index, path);
  return index;
}

// Point 2 of the file comment: the limits again, on what urdfdom built.
void checkUrdfdomModel(const urdf::ModelInterface& urdf, const LineIndex& index, const std::string& path) {
  if (urdf.links_.size() > kMaxUrdfLinks) tooMany(path, "link");
  if (urdf.joints_.size() > kMaxUrdfLinks) tooMany(path, "joint");
  const auto line = [&](const std::map<std::string, int>& lines, const std::string& name) {
    const auto it = lines.find(name);
    return it == lines.end() ? path : fmt::format("{}:{}", path, it->second);
  };
  requireUtf8(path, "robot name", urdf.name_);
  for (const auto& [name, link] : urdf.links_) requireUtf8(line(index.link, name), fmt::format("link {}", quoted(name)), name);
  std::vector<Edge> edges;
  for (const auto& [name, joint] : urdf.joints_) {
    requireUtf8(line(index.joint, name), fmt::format("joint {}", quoted(name)), name);
    edges.push_back({name, joint->parent_link_name, joint->child_link_name});
  }
  checkTreeShape(edges, index, path);
}

// urdfdom links hold their children by shared_ptr: a link that is its own
// child (a cycle) would never be freed, and freeing a deep chain would recurse
// once per link. Emptied while the link map still holds every link, each link
// is then freed on its own.
struct UnlinkOnExit {
  urdf::ModelInterfaceSharedPtr model;
  ~UnlinkOnExit() {
    if (!model) return;
    for (auto& entry : model->links_) {
      entry.second->child_links.clear();
      entry.second->child_joints.clear();
      entry.second->parent_joint.reset();
    }
  }
};

Mat3 toMatrix(const urdf::Rotation& r) {
  return Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
}

SE3 toSE3(const urdf::Pose& pose) {
  return {snapRotation(toMatrix(pose.rotation)), Vec3(pose.position.x, pose.position.y, pose.position.z)};
}

// How far from positive semi-definite a rotational inertia may be and still
// count as rounding: its smallest principal moment may be below zero by
// kPsdTolerance times its largest. URDF exporters write each entry to at least
// six significant digits, a relative error of at most 5e-7 of the largest
// entry (which, for a PSD tensor, is at most its largest moment); a 3x3
// perturbation whose entries are all below e has a spectral norm below 3e, so
// by Weyl's inequality the rounding moves an eigenvalue by at most 1.5e-6 of
// the largest moment. The scale is the body's own: a sensor link of 1e-6 kg
// whose tensor is off by -3.5e-8 (its own size) is negligible once merged into
// a body of 1 kg, and that merged body, what the dynamics use, is what decides.
constexpr double kPsdTolerance = 1.5e-6;

struct PrincipalMoments {
  double smallest = 0, largest = 0;
  bool psd() const { return smallest >= -kPsdTolerance * std::max(0.0, largest); }
};

PrincipalMoments principalMoments(const Mat3& I) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(I, Eigen::EigenvaluesOnly);
  return {eig.eigenvalues().minCoeff(), eig.eigenvalues().maxCoeff()};
}

class Builder {
 public:
  Builder(const std::string& path, const LineIndex& lines, BaseType base) : path_(path), lines_(lines), base_(base) {}

  Model build(const urdf::ModelInterface& urdf) {
    model_.name = urdf.getName();
    model_.sourcePath = path_;
    model_.floatingBase = base_ == BaseType::Floating;
    model_.planarBase = base_ == BaseType::Planar;
    model_.bodies.push_back(Body{});  // world
    model_.bodies[0].link = "world";
    const urdf::LinkConstSharedPtr root = urdf.getRoot();
    if (!root) fail(path_, "", "no root link");
    int rootBody = 0;
    if (base_ != BaseType::Fixed) {
      // The joint the layout adds between the world and the root link: always
      // `root_joint` (Pinocchio's name for it), a free flyer or a planar joint
      // in the world's x-y plane.
      Body b;
      b.link = root->name;
      b.parent = 0;
      b.joint.name = "root_joint";
      setMultiDof(b.joint, base_ == BaseType::Floating ? JointType::FreeFlyer : JointType::Planar);
      b.inertia = linkInertia(*root, 1);
      rootBody = addBody(std::move(b));
    } else {
      linkInertia(*root, 0);  // checked, then unused: the world does not move
    }
    model_.frames.push_back({root->name, rootBody, SE3::Identity(), ""});
    visitTree(*root, rootBody);
    assignIndices();
    checkMergedInertia();
    checkMovingInertia();
    reportMimics(urdf);
    return std::move(model_);
  }

 private:
  std::string where(const char* kind, const std::string& name) const {
    const auto& map = std::string(kind) == "link" ? lines_.link : lines_.joint;
    const auto it = map.find(name);
    return it == map.end() ? path_ : fmt::format("{}:{}", path_, it->second);
  }
  [[noreturn]] void failAt(const char* kind, const std::string& name, const std::string& what) const {
    fail(where(kind, name), fmt::format("{} {}", kind, quoted(name)), what);
  }
  double number(const char* kind, const std::string& name, const char* element, double x) const {
    return requireMagnitude(where(kind, name), fmt::format("{} {}: {}", kind, quoted(name), element), x);
  }

  int addBody(Body b) {
    model_.bodies.push_back(std::move(b));
    const int i = model_.numBodies() - 1;
    model_.bodies[model_.bodies[i].parent].children.push_back(i);
    return i;
  }

  // The link's inertia in its own frame. Whether it is positive semi-definite
  // is judged on the body it is merged into (checkMergedInertia); a link that
  // is not on its own is remembered, to be named.
  Inertia linkInertia(const urdf::Link& link, int body) {
    if (!link.inertial) return {};
    const urdf::Inertial& in = *link.inertial;
    const double v[] = {in.mass, in.ixx, in.ixy, in.ixz, in.iyy, in.iyz, in.izz,
                        in.origin.position.x, in.origin.position.y, in.origin.position.z};
    for (double x : v)
      if (!std::isfinite(x)) failAt("link", link.name, "<inertial> has a non-finite number");
    for (double x : v) number("link", link.name, "<inertial>", x);
    if (in.mass < 0) failAt("link", link.name, fmt::format("negative mass {}", in.mass));
    Mat3 I;
    I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    const PrincipalMoments moments = principalMoments(I);
    if (!moments.psd()) indefinite_.push_back({link.name, body, moments.smallest});
    const SE3 origin = toSE3(in.origin);
    return {in.mass, origin.p, origin.R * I * origin.R.transpose()};
  }

  Vec3 jointAxis(const urdf::Joint& j) const {
    const Vec3 a(j.axis.x, j.axis.y, j.axis.z);
    if (!a.allFinite()) failAt("joint", j.name, "<axis> has a non-finite component");
    const double n = a.stableNorm();  // no overflow for components near 1e308
    if (n < 1e-9) failAt("joint", j.name, "<axis> has zero length");
    if (n == 1.0) return a;
    return a.stableNormalized();
  }

  static void setMultiDof(Joint& j, JointType type) {
    j.type = type;
    const bool ff = type == JointType::FreeFlyer;
    j.urdfType = ff ? "floating" : "planar";
    j.nq = ff ? 7 : 4;
    j.nv = ff ? 6 : 3;
    j.axis = Vec3::UnitZ();  // the planar joint's plane normal; unused by a free flyer
  }

  // A planar joint moves in the x-y plane of its joint frame (<origin>): the
  // URDF's <axis> (the plane's normal) must be +z. Any other plane is the same
  // joint with <origin> rotated so that its z axis is the normal; refused
  // rather than rotated here, which would need a second fixed rotation to keep
  // the child link frame where URDF puts it and a choice of in-plane x axis
  // (docs/design.md, "Conventions").
  void checkPlanarAxis(const urdf::Joint& j) const {
    const Vec3 a(j.axis.x, j.axis.y, j.axis.z);
    if (!a.allFinite()) failAt("joint", j.name, "<axis> has a non-finite component");
    if (a.x() == 0.0 && a.y() == 0.0 && a.z() > 0.0) return;
    failAt("joint", j.name,
           fmt::format("planar joint with <axis> [{:g}, {:g}, {:g}] (urdfdom reads a missing <axis> as [1, 0, 0]): proxgen "
                       "supports planar joints in the x-y plane of the joint frame only, <axis xyz=\"0 0 1\">; rotate the "
                       "joint's <origin> so that its z axis is the plane's normal",
                       a.x(), a.y(), a.z()));
  }

  // A free flyer hangs from the world only (a link welded to it: the root of a
  // fixed base, or links fixed to it): the generated solvers eliminate a free
  // flyer as a root body (docs/design.md, "Conventions").
  void checkFloatingJoint(const urdf::Joint& j, int parentBody) const {
    if (parentBody == 0) return;
    const std::string parent = quoted(j.parent_link_name);
    if (base_ == BaseType::Floating && parentBody == 1)
      failAt("joint", j.name,
             fmt::format("floating joint on link {}, which `base: floating` already makes a free flyer: a floating joint "
                         "in the file is the floating base itself (use `base: fixed` with it), not one below it",
                         parent));
    failAt("joint", j.name,
           fmt::format("floating joint below link {}, which moves: proxgen supports a floating joint only on a link fixed "
                       "to the world (the root link of a fixed base, or a link welded to it)",
                       parent));
  }

  // Depth-first over the URDF tree from `root`, without recursion (an explicit
  // stack of the links being visited, as deep as the tree). urdfdom keeps
  // children sorted by joint name, which is also the order Pinocchio's URDF
  // parser produces; bodies and frames come out in the order of the recursive
  // walk this replaced.
  void visitTree(const urdf::Link& root, int rootBody) {
    struct Visit {
      const urdf::Link* link;
      int body;         // the body the link lives on
      SE3 linkInBody;   // the link's placement on it
      std::size_t next; // next child joint to visit
    };
    std::vector<Visit> stack{{&root, rootBody, SE3::Identity(), 0}};
    while (!stack.empty()) {
      Visit& top = stack.back();
      if (top.next == top.link->child_joints.size()) {
        stack.pop_back();
        continue;
      }
      const urdf::Link& link = *top.link;
      const int body = top.body;
      const SE3 linkInBody = top.linkInBody;
      const urdf::JointSharedPtr& j = link.child_joints[top.next++];
      const urdf::Link* child = nullptr;
      for (const auto& c : link.child_links)
        if (c->name == j->child_link_name) child = c.get();
      if (!child) failAt("joint", j->name, fmt::format("child link {} not found", quoted(j->child_link_name)));
      const urdf::Pose& o = j->parent_to_joint_origin_transform;
      const double ov[] = {o.position.x, o.position.y, o.position.z, o.rotation.x, o.rotation.y, o.rotation.z, o.rotation.w};
      for (double x : ov)
        if (!std::isfinite(x)) failAt("joint", j->name, "<origin> has a non-finite number");
      for (double x : {o.position.x, o.position.y, o.position.z}) number("joint", j->name, "<origin> xyz", x);
      const SE3 origin = linkInBody * toSE3(o);
      switch (j->type) {
        case urdf::Joint::FIXED: {
          // Merge: the child link's inertia joins this body; the link stays a frame.
          mergeInertia(body, linkInertia(*child, body).transformed(origin));
          model_.frames.push_back({child->name, body, origin, j->name});
          stack.push_back({child, body, origin, 0});  // `top` is invalid from here
          break;
        }
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
        case urdf::Joint::PRISMATIC: {
          Body b;
          b.link = child->name;
          b.parent = body;
          b.treePlacement = origin;
          b.joint.name = j->name;
          b.joint.type = j->type == urdf::Joint::PRISMATIC ? JointType::Prismatic : JointType::Revolute;
          b.joint.urdfType = j->type == urdf::Joint::PRISMATIC ? "prismatic"
                             : j->type == urdf::Joint::REVOLUTE ? "revolute"
                                                                : "continuous";
          b.joint.axis = jointAxis(*j);
          if (j->limits) {
            const urdf::JointLimits& l = *j->limits;
            b.joint.hasPositionLimits = j->type != urdf::Joint::CONTINUOUS;
            b.joint.lower = l.lower;
            b.joint.upper = l.upper;
            b.joint.velocityLimit = l.velocity;
            b.joint.effortLimit = l.effort;
          }
          if (j->mimic) b.joint.mimicOf = j->mimic->joint_name;
          b.inertia = linkInertia(*child, model_.numBodies());
          const int i = addBody(std::move(b));
          model_.frames.push_back({child->name, i, SE3::Identity(), j->name});
          stack.push_back({child, i, SE3::Identity(), 0});  // `top` is invalid from here
          break;
        }
        case urdf::Joint::FLOATING:
        case urdf::Joint::PLANAR: {
          const bool floating = j->type == urdf::Joint::FLOATING;
          if (floating) checkFloatingJoint(*j, body);
          Body b;
          b.link = child->name;
          b.parent = body;
          b.treePlacement = origin;
          b.joint.name = j->name;
          setMultiDof(b.joint, floating ? JointType::FreeFlyer : JointType::Planar);
          if (!floating) checkPlanarAxis(*j);
          b.inertia = linkInertia(*child, model_.numBodies());
          const int i = addBody(std::move(b));
          model_.frames.push_back({child->name, i, SE3::Identity(), j->name});
          stack.push_back({child, i, SE3::Identity(), 0});  // `top` is invalid from here
          break;
        }
        default:
          failAt("joint", j->name, "unknown joint type");
      }
    }
  }

  void assignIndices() {
    int q = 0, v = 0;
    for (int i = 1; i < model_.numBodies(); ++i) {
      Joint& j = model_.bodies[i].joint;
      j.idx_q = q;
      j.idx_v = v;
      q += j.nq;
      v += j.nv;
    }
    model_.nq = q;
    model_.nv = v;
  }

  // What the dynamics use is each moving body's inertia after fixed-joint
  // merging: it must be positive semi-definite (kPsdTolerance, on its own
  // scale). A link that is not on its own but whose body is gets a warning
  // naming it; the world (body 0, a fixed base's root and what is welded to
  // it) never moves, so its inertia is never used.
  void checkMergedInertia() {
    for (int i = 1; i < model_.numBodies(); ++i) {
      const PrincipalMoments m = principalMoments(model_.bodies[i].inertia.Ic);
      if (m.psd()) continue;
      const Body& b = model_.bodies[i];
      failAt("link", b.link,
             fmt::format("rotational inertia is not positive semi-definite (smallest principal moment {:g}, largest {:g}, "
                         "of body {} with the links fixed to it merged; refused beyond {:g} of the largest)",
                         m.smallest, m.largest, quoted(b.link), kPsdTolerance));
    }
    for (const IndefiniteLink& l : indefinite_) {
      const std::string body = quoted(model_.bodies[l.body].link);
      const std::string accepted =
          l.body == 0 ? "it is merged by fixed joints into the world, where its inertia has no effect"
          : model_.bodies[l.body].link == l.link
              ? fmt::format("its body {}, with the links fixed to it merged, is positive semi-definite", body)
              : fmt::format("it is merged by fixed joints into body {}, whose merged inertia is positive semi-definite", body);
      model_.warnings.push_back(
          warn(where("link", l.link), fmt::format("link {}", quoted(l.link)),
               fmt::format("rotational inertia is not positive semi-definite (smallest principal moment {:g}); accepted: {}",
                           l.smallest, accepted)));
    }
  }

  // Every moving joint must move something with inertia about its own axes,
  // otherwise the articulated inertia D_i is zero and every solver divides by
  // it; and at least kMinMovedInertia, so that D_i^-1 cannot overflow.
  void checkMovingInertia() {
    const int N = model_.numBodies();
    std::vector<Mat6> composite(N, Mat6::Zero());
    for (int i = N - 1; i >= 1; --i) {
      composite[i] += model_.bodies[i].inertia.matrix();
      const Mat6X S = model_.motionSubspace(i);
      const Eigen::MatrixXd D = S.transpose() * composite[i] * S;
      const double scale = std::max(1e-300, composite[i].cwiseAbs().maxCoeff());
      const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(D).eigenvalues().minCoeff();
      const Body& b = model_.bodies[i];
      if (!(smallest > 1e-14 * scale) || composite[i].cwiseAbs().maxCoeff() == 0.0) {
        failAt("joint", b.joint.name,
               fmt::format("moves link {} and its descendants, which have no mass or inertia about the "
                           "joint's axes (the dynamics would be singular)",
                           quoted(b.link)));
      }
      if (smallest < kMinMovedInertia)
        failAt("joint", b.joint.name,
               fmt::format("moves link {} and its descendants, whose inertia about the joint's axes is only {:g}, "
                           "below the {:g} proxgen accepts (the solvers divide by it, and would overflow)",
                           quoted(b.link), smallest, kMinMovedInertia));
      const int p = model_.bodies[i].parent;
      if (p > 0) {
        const Mat6 X = model_.bodies[i].treePlacement.motionMatrixInv();
        composite[p] += X.transpose() * composite[i] * X;
      }
    }
  }

  // Mimic joints are solved as independent joints: said once per file, with
  // the count. A <mimic> naming a joint the file does not have is named.
  void reportMimics(const urdf::ModelInterface& urdf) {
    std::vector<const Joint*> mimics;
    for (int i = 1; i < model_.numBodies(); ++i)
      if (!model_.bodies[i].joint.mimicOf.empty()) mimics.push_back(&model_.bodies[i].joint);
    for (const Joint* j : mimics)
      if (!urdf.joints_.count(j->mimicOf))
        model_.warnings.push_back(warn(where("joint", j->name), fmt::format("joint {}", quoted(j->name)),
                                       fmt::format("<mimic> names joint {}, which is not in the file",
                                                   quoted(j->mimicOf))));
    if (mimics.empty()) return;
    model_.warnings.push_back(warn(
        path_, "<mimic>",
        fmt::format("{} joint{} mimic{} another ({} mimics {}{}): proxgen solves mimic joints as independent joints, "
                    "each with its own q, v and tau",
                    mimics.size(), mimics.size() == 1 ? "" : "s", mimics.size() == 1 ? "s" : "", quoted(mimics[0]->name),
                    quoted(mimics[0]->mimicOf), mimics.size() == 1 ? "" : ", ...")));
  }

  struct IndefiniteLink {
    std::string link;
    int body;
    double smallest;
  };

  std::string path_;
  const LineIndex& lines_;
  BaseType base_;
  Model model_;
  std::vector<IndefiniteLink> indefinite_;
  std::map<int, Vec3> firstMoments_;  // per merged body: sum of m |c| of its parts, per axis

  // Adds a fixed child's inertia to body `body`, then snaps what is round-off
  // of the sum (the generic and generated solvers then see the same exact
  // zeros, and the generator folds them). Parts placed symmetrically (the
  // quadruped's four rotors at +-x, +-y) cancel in exact arithmetic, but the
  // floating-point sum leaves a residue such as 2^-64 = 5.4e-20 in a product
  // of inertia, which would survive as a live term `5.4e-20*v[4]`. A sum of n
  // terms is off by at most about n eps times the sum of their magnitudes, so
  // a result below 4 eps of that magnitude is indistinguishable from zero:
  //   - centre of mass, axis k: the first moment m c_k = sum m_i c_ik, against
  //     sum m_i |c_ik| over the parts;
  //   - rotational inertia, entry (r, c): against trace(Ic) (a positive
  //     semi-definite tensor has |I_rc| <= sqrt(I_rr I_cc) <= trace / 2, and
  //     every term of the sum is one, so the trace bounds their magnitudes).
  // A physical entry is never that small relative to its body: 4 eps = 9e-16.
  void mergeInertia(int body, const Inertia& part) {
    Inertia& I = model_.bodies[std::size_t(body)].inertia;
    auto [it, first] = firstMoments_.emplace(body, Vec3::Zero());
    if (first) it->second = I.mass * I.com.cwiseAbs();
    it->second += part.mass * part.com.cwiseAbs();
    I = I + part;
    constexpr double kRoundOff = 4 * std::numeric_limits<double>::epsilon();
    for (int k = 0; k < 3; ++k)
      if (std::abs(I.mass * I.com[k]) <= kRoundOff * it->second[k]) I.com[k] = 0.0;
    const double trace = I.Ic.trace();
    for (int k = 0; k < 9; ++k)
      if (std::abs(I.Ic.data()[k]) <= kRoundOff * trace) I.Ic.data()[k] = 0.0;
  }
};

}  // namespace

Model parseUrdf(const std::string& xml, const std::string& path, BaseType base) {
  // The two XML parsers (tinyxml2 here, TinyXML inside urdfdom) each build a
  // DOM of ~100-200 bytes per node: bounded through the tags before either runs.
  const std::size_t tags = std::size_t(std::count(xml.begin(), xml.end(), '<'));
  if (tags > kMaxUrdfTags)
    fail(path, "", fmt::format("has {} markup tags ('<'), more than the {} proxgen reads", tags, kMaxUrdfTags));
  scanMarkup(xml, path);
  const LineIndex lines = indexLines(xml, path);
  UnlinkOnExit urdf;
  std::string urdfdomError;
  {
    std::lock_guard<std::mutex> lock(g_urdfdomMutex);
    Capture capture;
    console_bridge::useOutputHandler(&capture);
    try {
      urdf.model = urdf::parseURDF(xml);
    } catch (const std::exception& e) {
      capture.errors = oneLine(e.what());
      urdf.model.reset();
    }
    console_bridge::restorePreviousOutputHandler();
    urdfdomError = capture.errors;
  }
  if (!urdf.model || !urdfdomError.empty())
    fail(path, "", fmt::format("not a valid URDF: {}", urdfdomError.empty() ? "urdfdom rejected it" : urdfdomError));
  checkUrdfdomModel(*urdf.model, lines, path);
  return Builder(path, lines, base).build(*urdf.model);
}

Model parseUrdf(const std::string& xml, const std::string& path, bool floatingBase) {
  return parseUrdf(xml, path, floatingBase ? BaseType::Floating : BaseType::Fixed);
}

Model loadUrdf(const std::string& path, BaseType base) {
  return parseUrdf(readInputFile(path, kMaxUrdfBytes, "URDF"), path, base);
}

Model loadUrdf(const std::string& path, bool floatingBase) {
  return loadUrdf(path, floatingBase ? BaseType::Floating : BaseType::Fixed);
}

}  // namespace proxgen
