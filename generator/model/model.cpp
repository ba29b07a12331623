#include "model/model.hpp"

#include <fmt/format.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <set>

#include "model/error.hpp"
#include "model/input.hpp"
#include "model/warn.hpp"

namespace proxgen {

const char* jointTypeName(JointType t) {
  switch (t) {
    case JointType::Revolute: return "revolute";
    case JointType::Prismatic: return "prismatic";
    case JointType::FreeFlyer: return "floating";
    case JointType::Planar: return "planar";
  }
  return "?";
}

int Model::findFrame(const std::string& link) const {
  for (int f = 0; f < int(frames.size()); ++f)
    if (frames[f].name == link) return f;
  return -1;
}

int Model::findJointBody(const std::string& joint) const {
  for (int i = 1; i < numBodies(); ++i)
    if (bodies[i].joint.name == joint) return i;
  return -1;
}

Mat6X Model::motionSubspace(int i) const {
  const Joint& j = bodies[i].joint;
  switch (j.type) {
    case JointType::Revolute: {
      Mat6X S = Mat6X::Zero(6, 1);
      S.block<3, 1>(3, 0) = j.axis;
      return S;
    }
    case JointType::Prismatic: {
      Mat6X S = Mat6X::Zero(6, 1);
      S.block<3, 1>(0, 0) = j.axis;
      return S;
    }
    case JointType::FreeFlyer: return Mat6X::Identity(6, 6);
    case JointType::Planar: {
      // Constant in the body frame: linear x, linear y, angular z (no joint bias term).
      Mat6X S = Mat6X::Zero(6, 3);
      S(0, 0) = S(1, 1) = S(5, 2) = 1.0;
      return S;
    }
  }
  return {};
}

SE3 Model::jointPlacement(int i, const Eigen::Ref<const VecX>& q) const {
  const Body& b = bodies[i];
  const Joint& j = b.joint;
  switch (j.type) {
    case JointType::Revolute: return b.treePlacement * SE3{axisAngle(j.axis, q[j.idx_q]), Vec3::Zero()};
    case JointType::Prismatic: return b.treePlacement * SE3{Mat3::Identity(), j.axis * q[j.idx_q]};
    case JointType::FreeFlyer: {
      // q = [x y z qx qy qz qw]; the quaternion is used as given (callers normalise).
      const Eigen::Quaterniond quat(q[j.idx_q + 6], q[j.idx_q + 3], q[j.idx_q + 4], q[j.idx_q + 5]);
      return b.treePlacement * SE3{quat.toRotationMatrix(), q.segment<3>(j.idx_q)};
    }
    case JointType::Planar: {
      // q = [x y c s]; (c, s) is used as given (callers normalise), R = [c -s 0; s c 0; 0 0 1].
      const double c = q[j.idx_q + 2], s = q[j.idx_q + 3];
      Mat3 R;
      R << c, -s, 0, s, c, 0, 0, 0, 1;
      return b.treePlacement * SE3{R, Vec3(q[j.idx_q], q[j.idx_q + 1], 0.0)};
    }
  }
  return {};
}

VecX Model::neutral() const {
  VecX q = VecX::Zero(nq);
  for (int i = 1; i < numBodies(); ++i) {
    const Joint& j = bodies[i].joint;
    if (j.type == JointType::FreeFlyer) q[j.idx_q + 6] = 1.0;
    if (j.type == JointType::Planar) q[j.idx_q + 2] = 1.0;
  }
  return q;
}

std::vector<int> Model::pathToRoot(int i) const {
  std::vector<int> path;
  for (; i > 0; i = bodies[i].parent) path.push_back(i);
  return path;
}

int System::findConstraint(const std::string& name) const {
  for (int c = 0; c < int(constraints.size()); ++c)
    if (constraints[c].name == name) return c;
  return -1;
}

std::vector<int> System::supportBodies() const {
  std::set<int> support;
  for (const Constraint& c : constraints)
    for (int i : model.pathToRoot(c.body)) support.insert(i);
  return {support.begin(), support.end()};
}

System bindLayout(Model model, const Layout& layout) {
  System sys;
  sys.layoutPath = layout.sourcePath;
  sys.mu = layout.mu;
  sys.iterations = layout.iterations;
  sys.functions = layout.functions;
  if (layout.hasGravity) model.gravity = layout.gravity;
  int row = 0;
  for (std::size_t k = 0; k < layout.constraints.size(); ++k) {
    Constraint c = layout.constraints[k];
    const std::string element = fmt::format("constraints[{}] {}", k, quoted(c.name));
    const int f = model.findFrame(c.link);
    if (f < 0) {
      // The line of `link:` and the nearest link names: most unknown links are typos.
      std::vector<std::string> links;
      for (const Frame& frame : model.frames) links.push_back(frame.name);
      fail(c.linkLine > 0 ? fmt::format("{}:{}", layout.sourcePath, c.linkLine) : layout.sourcePath, element,
           fmt::format("link {} is not in {} (closest: {})", quoted(c.link), model.sourcePath,
                       quotedList(closestNames(c.link, links, 3), ", ")));
    }
    c.body = model.frames[f].body;
    // Body 0 is the world: the link is welded to it and its rows of J are zero,
    // which is almost always a wrong link name (or a fixed base meant floating).
    if (c.body == 0)
      model.warnings.push_back(warn(layout.sourcePath, element,
                                    fmt::format("link {} is fixed to the world (merged into it by fixed joints or the "
                                                "root of a fixed base): the constraint constrains nothing",
                                                quoted(c.link))));
    c.placement = model.frames[f].placement * c.offset;
    c.row = row;
    row += c.rows();
    sys.constraints.push_back(std::move(c));
  }
  sys.nc = row;
  sys.model = std::move(model);
  return sys;
}

// --- input files, names and numbers (shared by the URDF, layout and state readers)

std::string readInputFile(const std::string& path, std::size_t maxBytes, const char* kind) {
  // O_NONBLOCK: opening a FIFO with no writer would otherwise block in open().
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  // The system's reason, in its words ("No such file or directory",
  // "Permission denied"): what the user must fix is outside proxgen.
  if (fd < 0) fail(path, "", fmt::format("cannot open the {} file: {}", kind, std::strerror(errno)));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) fail(path, "", fmt::format("cannot read the {} file: {}", kind, std::strerror(errno)));
  if (S_ISDIR(st.st_mode)) fail(path, "", fmt::format("cannot read the {} file: {}", kind, std::strerror(EISDIR)));
  if (!S_ISREG(st.st_mode))
    fail(path, "", fmt::format("is not a regular file (a FIFO, device or socket): proxgen reads {} files only from "
                               "regular files, whose size is known before reading",
                               kind));
  if (std::uintmax_t(st.st_size) > maxBytes)
    fail(path, "", fmt::format("file is {} bytes, more than the {} bytes proxgen reads", st.st_size, maxBytes));
  std::string text(std::size_t(st.st_size), '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(path, "", fmt::format("cannot read the {} file: {}", kind, std::strerror(errno)));
    if (n == 0) break;  // shrank while read: what is there is the file
    got += std::size_t(n);
  }
  text.resize(got);
  return text;
}

bool isValidUtf8(const std::string& s, std::size_t* badOffset) {
  const auto* b = reinterpret_cast<const unsigned char*>(s.data());
  const std::size_t n = s.size();
  for (std::size_t k = 0; k < n;) {
    const unsigned char c = b[k];
    std::size_t len = 0;
    unsigned lo = 0x80, hi = 0xbf;  // allowed range of the second byte
    if (c < 0x80) len = 1;
    else if (c >= 0xc2 && c <= 0xdf) len = 2;
    else if (c == 0xe0) len = 3, lo = 0xa0;           // no overlong 3-byte forms
    else if (c >= 0xe1 && c <= 0xec) len = 3;
    else if (c == 0xed) len = 3, hi = 0x9f;           // no surrogates
    else if (c >= 0xee && c <= 0xef) len = 3;
    else if (c == 0xf0) len = 4, lo = 0x90;           // no overlong 4-byte forms
    else if (c >= 0xf1 && c <= 0xf3) len = 4;
    else if (c == 0xf4) len = 4, hi = 0x8f;           // nothing above U+10FFFF
    bool ok = len > 0 && k + len <= n;
    for (std::size_t i = 1; ok && i < len; ++i) {
      const unsigned char t = b[k + i];
      ok = i == 1 ? (t >= lo && t <= hi) : (t >= 0x80 && t <= 0xbf);
    }
    if (!ok) {
      if (badOffset) *badOffset = k;
      return false;
    }
    k += len;
  }
  return true;
}

void requireUtf8(const std::string& file, const std::string& element, const std::string& name) {
  std::size_t at = 0;
  if (!isValidUtf8(name, &at))
    fail(file, element,
         fmt::format("the name is not valid UTF-8 (byte 0x{:02x} at offset {}); names must be UTF-8 text",
                     static_cast<unsigned char>(name[at]), at));
}

double requireMagnitude(const std::string& file, const std::string& element, double x) {
  if (!std::isfinite(x)) fail(file, element, "is not finite");
  if (std::abs(x) > kMaxInputMagnitude)
    fail(file, element,
         fmt::format("{:g} is beyond the largest magnitude proxgen accepts ({:g}): the dynamics would overflow", x,
                     kMaxInputMagnitude));
  return x;
}

}  // namespace proxgen
