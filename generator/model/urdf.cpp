// URDF -> Model.
//
// urdfdom does the parsing and the tree checks (two roots, unknown parents).
// Before it, tinyxml2 checks that the file is well-formed XML, records the line
// of every <link> and <joint>, so our own errors can point at the element, and
// names a joint that closes a cycle. After it, we walk the tree depth-first, merge fixed joints and
// validate every number that will reach a solver.
#include "model/urdf.hpp"

#include <console_bridge/console.h>
#include <fmt/format.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <vector>

#include "model/error.hpp"

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

// urdfdom only says "no root link" for a closed chain; this names a joint that
// closes it. It also refuses a tree deeper than kMaxTreeDepth, which the
// depth-first Builder would recurse into until the stack overflows. Each link's
// depth is found once, so this stays linear in the number of links (a 50 MB
// chain). `parentJoint` maps a child link to (parent link, joint).
void checkTreeShape(const std::map<std::string, std::pair<std::string, std::string>>& parentJoint,
                    const LineIndex& index, const std::string& path) {
  const auto failAtJoint = [&](const std::string& joint, const std::string& what) {
    const auto line = index.joint.find(joint);
    fail(line == index.joint.end() ? path : fmt::format("{}:{}", path, line->second),
         fmt::format("joint {}", quoted(joint)), what);
  };
  std::map<std::string, std::size_t> depth;  // joints between a link and its root link
  std::vector<std::string> walk;
  for (const auto& start : parentJoint) {
    // Up to a root or to a link whose depth is known. More steps up than there
    // are joints means the walk went round a cycle.
    walk.clear();
    std::string link = start.first;
    while (parentJoint.count(link) && !depth.count(link)) {
      const auto& [parent, joint] = parentJoint.at(link);
      if (walk.size() > parentJoint.size()) failAtJoint(joint, "closes a kinematic cycle: a URDF must be a tree");
      walk.push_back(link);
      link = parent;
    }
    std::size_t d = depth.count(link) ? depth.at(link) : 0;
    for (auto it = walk.rbegin(); it != walk.rend(); ++it) {
      depth[*it] = ++d;
      if (d > kMaxTreeDepth)
        failAtJoint(parentJoint.at(*it).second,
                    fmt::format("is {} joints below the root link; proxgen reads trees at most {} joints deep", d,
                                kMaxTreeDepth));
    }
  }
}

LineIndex indexLines(const std::string& xml, const std::string& path) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
    fail(fmt::format("{}:{}", path, doc.ErrorLineNum()), "", fmt::format("not well-formed XML ({})", doc.ErrorName()));
  }
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) fail(path, "", "no <robot> element at the top level: not a URDF file");
  LineIndex index;
  std::map<std::string, std::pair<std::string, std::string>> parentJoint;
  std::size_t links = 0, joints = 0;
  for (auto* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    // Bounded before urdfdom builds its own copy and we build the model.
    links += std::string(e->Name()) == "link";
    joints += std::string(e->Name()) == "joint";
    if (links > kMaxUrdfLinks || joints > kMaxUrdfLinks)
      fail(fmt::format("{}:{}", path, e->GetLineNum()), "",
           fmt::format("more than {} <{}> elements: proxgen reads robots of at most {} links", kMaxUrdfLinks,
                       e->Name(), kMaxUrdfLinks));
    const char* name = e->Attribute("name");
    if (!name) continue;
    if (std::string(e->Name()) == "link") index.link.emplace(name, e->GetLineNum());
    if (std::string(e->Name()) != "joint") continue;
    index.joint.emplace(name, e->GetLineNum());
    const tinyxml2::XMLElement* parent = e->FirstChildElement("parent");
    const tinyxml2::XMLElement* child = e->FirstChildElement("child");
    if (parent && child && parent->Attribute("link") && child->Attribute("link"))
      parentJoint.emplace(child->Attribute("link"), std::make_pair(std::string(parent->Attribute("link")), std::string(name)));
  }
  checkTreeShape(parentJoint, index, path);
  return index;
}

Mat3 toMatrix(const urdf::Rotation& r) {
  return Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
}

// Rotation entries within a few ulps of 0 or +-1 are what an rpy of pi/2 in
// decimal leaves behind; they are snapped here, in the Model, so the generic and
// the generated solvers see the same numbers and the generator can fold them.
Mat3 snapRotation(Mat3 R) {
  for (int k = 0; k < 9; ++k) {
    double& x = R.data()[k];
    if (std::abs(x) < 1e-15) x = 0.0;
    else if (std::abs(x - 1.0) < 1e-15) x = 1.0;
    else if (std::abs(x + 1.0) < 1e-15) x = -1.0;
  }
  return R;
}

SE3 toSE3(const urdf::Pose& pose) {
  return {snapRotation(toMatrix(pose.rotation)), Vec3(pose.position.x, pose.position.y, pose.position.z)};
}

class Builder {
 public:
  Builder(const std::string& path, const LineIndex& lines, bool floating)
      : path_(path), lines_(lines), floating_(floating) {}

  Model build(const urdf::ModelInterface& urdf) {
    model_.name = urdf.getName();
    model_.sourcePath = path_;
    model_.floatingBase = floating_;
    model_.bodies.push_back(Body{});  // world
    model_.bodies[0].link = "world";
    const urdf::LinkConstSharedPtr root = urdf.getRoot();
    if (!root) fail(path_, "", "no root link");
    int rootBody = 0;
    if (floating_) {
      Body b;
      b.link = root->name;
      b.parent = 0;
      b.joint.name = "root_joint";
      b.joint.type = JointType::FreeFlyer;
      b.joint.urdfType = "floating";
      b.joint.nq = 7;
      b.joint.nv = 6;
      b.inertia = linkInertia(*root);
      rootBody = addBody(std::move(b));
    }
    model_.frames.push_back({root->name, rootBody, SE3::Identity(), ""});
    visitChildren(*root, rootBody, SE3::Identity());
    assignIndices();
    checkMovingInertia();
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

  int addBody(Body b) {
    model_.bodies.push_back(std::move(b));
    const int i = model_.numBodies() - 1;
    model_.bodies[model_.bodies[i].parent].children.push_back(i);
    return i;
  }

  Inertia linkInertia(const urdf::Link& link) const {
    if (!link.inertial) return {};
    const urdf::Inertial& in = *link.inertial;
    const double v[] = {in.mass, in.ixx, in.ixy, in.ixz, in.iyy, in.iyz, in.izz,
                        in.origin.position.x, in.origin.position.y, in.origin.position.z};
    for (double x : v)
      if (!std::isfinite(x)) failAt("link", link.name, "<inertial> has a non-finite number");
    if (in.mass < 0) failAt("link", link.name, fmt::format("negative mass {}", in.mass));
    Mat3 I;
    I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(I);
    const double scale = std::max(1.0, I.cwiseAbs().maxCoeff());
    if (eig.eigenvalues().minCoeff() < -1e-12 * scale)
      failAt("link", link.name,
             fmt::format("rotational inertia is not positive semi-definite (smallest principal moment {:g})",
                         eig.eigenvalues().minCoeff()));
    const SE3 origin = toSE3(in.origin);
    return {in.mass, origin.p, origin.R * I * origin.R.transpose()};
  }

  Vec3 jointAxis(const urdf::Joint& j) const {
    const Vec3 a(j.axis.x, j.axis.y, j.axis.z);
    if (!a.allFinite()) failAt("joint", j.name, "<axis> has a non-finite component");
    const double n = a.norm();
    if (n < 1e-9) failAt("joint", j.name, "<axis> has zero length");
    if (n == 1.0) return a;
    return a / n;
  }

  // Depth-first over the URDF children of `link`, which lives on `body` at
  // placement `linkInBody`. urdfdom keeps children sorted by joint name, which
  // is also the order Pinocchio's URDF parser produces.
  void visitChildren(const urdf::Link& link, int body, const SE3& linkInBody) {
    for (const urdf::JointSharedPtr& j : link.child_joints) {
      const urdf::LinkConstSharedPtr child = [&] {
        for (const auto& c : link.child_links)
          if (c->name == j->child_link_name) return urdf::LinkConstSharedPtr(c);
        return urdf::LinkConstSharedPtr();
      }();
      if (!child) failAt("joint", j->name, fmt::format("child link {} not found", quoted(j->child_link_name)));
      const urdf::Pose& o = j->parent_to_joint_origin_transform;
      const double ov[] = {o.position.x, o.position.y, o.position.z, o.rotation.x, o.rotation.y, o.rotation.z, o.rotation.w};
      for (double x : ov)
        if (!std::isfinite(x)) failAt("joint", j->name, "<origin> has a non-finite number");
      const SE3 origin = linkInBody * toSE3(o);
      switch (j->type) {
        case urdf::Joint::FIXED: {
          // Merge: the child link's inertia joins this body; the link stays a frame.
          model_.bodies[body].inertia = model_.bodies[body].inertia + linkInertia(*child).transformed(origin);
          model_.frames.push_back({child->name, body, origin, j->name});
          visitChildren(*child, body, origin);
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
          if (j->mimic) {
            b.joint.mimicOf = j->mimic->joint_name;
            model_.warnings.push_back(fmt::format("{}: joint {} mimics {}: solved as an independent joint",
                                                  where("joint", j->name), quoted(j->name),
                                                  quoted(j->mimic->joint_name)));
          }
          b.inertia = linkInertia(*child);
          const int i = addBody(std::move(b));
          model_.frames.push_back({child->name, i, SE3::Identity(), j->name});
          visitChildren(*child, i, SE3::Identity());
          break;
        }
        case urdf::Joint::FLOATING:
          failAt("joint", j->name,
                 "floating joints are only supported as the root (say `base: floating` in the layout)");
        case urdf::Joint::PLANAR:
          failAt("joint", j->name, "planar joints are not supported");
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

  // Every moving joint must move something with inertia about its own axes,
  // otherwise the articulated inertia D_i is zero and every solver divides by it.
  void checkMovingInertia() {
    const int N = model_.numBodies();
    std::vector<Mat6> composite(N, Mat6::Zero());
    for (int i = N - 1; i >= 1; --i) {
      composite[i] += model_.bodies[i].inertia.matrix();
      const Mat6X S = model_.motionSubspace(i);
      const Eigen::MatrixXd D = S.transpose() * composite[i] * S;
      const double scale = std::max(1e-300, composite[i].cwiseAbs().maxCoeff());
      const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(D).eigenvalues().minCoeff();
      if (!(smallest > 1e-14 * scale) || composite[i].cwiseAbs().maxCoeff() == 0.0) {
        const Body& b = model_.bodies[i];
        failAt("joint", b.joint.name,
               fmt::format("moves link {} and its descendants, which have no mass or inertia about the "
                           "joint's axes (the dynamics would be singular)",
                           quoted(b.link)));
      }
      const int p = model_.bodies[i].parent;
      if (p > 0) {
        const Mat6 X = model_.bodies[i].treePlacement.motionMatrixInv();
        composite[p] += X.transpose() * composite[i] * X;
      }
    }
  }

  std::string path_;
  const LineIndex& lines_;
  bool floating_;
  Model model_;
};

}  // namespace

Model parseUrdf(const std::string& xml, const std::string& path, bool floatingBase) {
  // The two XML parsers (tinyxml2 here, TinyXML inside urdfdom) each build a
  // DOM of ~100-200 bytes per node: bounded through the tags before either runs.
  const std::size_t tags = std::size_t(std::count(xml.begin(), xml.end(), '<'));
  if (tags > kMaxUrdfTags)
    fail(path, "", fmt::format("has {} markup tags ('<'), more than the {} proxgen reads", tags, kMaxUrdfTags));
  const LineIndex lines = indexLines(xml, path);
  urdf::ModelInterfaceSharedPtr urdf;
  std::string urdfdomError;
  {
    std::lock_guard<std::mutex> lock(g_urdfdomMutex);
    Capture capture;
    console_bridge::useOutputHandler(&capture);
    try {
      urdf = urdf::parseURDF(xml);
    } catch (const std::exception& e) {
      capture.errors = oneLine(e.what());
      urdf.reset();
    }
    console_bridge::restorePreviousOutputHandler();
    urdfdomError = capture.errors;
  }
  if (!urdf || !urdfdomError.empty()) fail(path, "", fmt::format("not a valid URDF: {}", urdfdomError.empty() ? "urdfdom rejected it" : urdfdomError));
  return Builder(path, lines, floatingBase).build(*urdf);
}

Model loadUrdf(const std::string& path, bool floatingBase) {
  // A directory opens as a stream on Linux and reports a size of 2^63 - 1.
  if (struct stat st {}; ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) fail(path, "", "is a directory, not a URDF file");
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) fail(path, "", "cannot open file");
  const std::streamoff size = in.tellg();
  if (size < 0) fail(path, "", "cannot read file (is it a directory?)");
  if (std::size_t(size) > kMaxUrdfBytes)
    fail(path, "", fmt::format("file is {} bytes, more than the {} bytes proxgen reads", size, kMaxUrdfBytes));
  std::string xml(std::size_t(size), '\0');
  in.seekg(0);
  if (!in.read(xml.data(), size)) fail(path, "", "cannot read file");
  return parseUrdf(xml, path, floatingBase);
}

}  // namespace proxgen
