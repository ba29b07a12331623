#include "model/model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "model/error.hpp"

namespace proxgen {

const char* jointTypeName(JointType t) {
  switch (t) {
    case JointType::Revolute: return "revolute";
    case JointType::Prismatic: return "prismatic";
    case JointType::FreeFlyer: return "floating";
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
  }
  return {};
}

VecX Model::neutral() const {
  VecX q = VecX::Zero(nq);
  for (int i = 1; i < numBodies(); ++i)
    if (bodies[i].joint.type == JointType::FreeFlyer) q[bodies[i].joint.idx_q + 6] = 1.0;
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
  if (layout.hasGravity) model.gravity = layout.gravity;
  int row = 0;
  for (std::size_t k = 0; k < layout.constraints.size(); ++k) {
    Constraint c = layout.constraints[k];
    const std::string element = fmt::format("constraints[{}] {}", k, quoted(c.name));
    const int f = model.findFrame(c.link);
    if (f < 0)
      fail(layout.sourcePath, element,
           fmt::format("link {} is not in {}", quoted(c.link), model.sourcePath));
    c.body = model.frames[f].body;
    c.placement = model.frames[f].placement * c.offset;
    c.row = row;
    row += c.rows();
    sys.constraints.push_back(std::move(c));
  }
  sys.nc = row;
  sys.model = std::move(model);
  return sys;
}

}  // namespace proxgen
