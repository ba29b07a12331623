// MuJoCo on the shared cases, timed by the suite as algorithm "mujoco"
// (docs/benchmarks.md, "Peers in the same run"). Per case: the case's URDF read by
// MuJoCo's own URDF parser, the layout's constraints as equality constraints (weld
// for 6d, connect for 3d) on the body proxgen attaches them to, and the case's
// state pool in MuJoCo's coordinates. One call = the state written into mjData
// and mj_forward.
//
// What the model keeps and drops (checked, not assumed: the constructor compares
// MuJoCo's unconstrained qacc with proxgen's generic ABA on the case's states and
// throws past a bound, so every smoke run of the suite re-checks it):
// - visual and collision elements are removed before MuJoCo reads the URDF, so no
//   mesh file is opened (proxgen reads neither);
// - fixed joints are fused into the moving parent (MuJoCo's URDF default, and what
//   proxgen does), inertias included; the constraint frames of fused links become
//   anchors/poses in the moving body, as proxgen's constraint placement is;
// - a floating base is a URDF "floating" joint named root_joint from a link named
//   "world" (MuJoCo makes it a free joint on the world body);
// - the equalities are added to the MJCF MuJoCo writes back (mj_saveLastXML), and
//   the reloaded model's numbers are then copied from the URDF-compiled one, since
//   the writer prints 6 significant digits.
#include <mujoco/mujoco.h>
#include <tinyxml2.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "algorithms/aba.hpp"
#include "algorithms/constrained_aba.hpp"
#include "algorithms/data.hpp"
#include "common.hpp"
#include "model/error.hpp"

namespace proxgen::bench {
namespace {

[[noreturn]] void mujocoError(const std::string& caseName, const std::string& what) {
  throw Error("mujoco, case " + caseName + ": " + what);
}

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The case's URDF as MuJoCo should read it: no geometry, fixed links fused, and for
// a floating base a free joint root_joint on the root link.
std::string urdfForMujoco(const BenchCase& c) {
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(c.sys.model.sourcePath.c_str()) != tinyxml2::XML_SUCCESS)
    mujocoError(c.name, "cannot read " + c.sys.model.sourcePath);
  tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) mujocoError(c.name, c.sys.model.sourcePath + " has no <robot>");
  for (tinyxml2::XMLElement* old = robot->FirstChildElement("mujoco"); old; old = robot->FirstChildElement("mujoco"))
    robot->DeleteChild(old);
  for (tinyxml2::XMLElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link")) {
    if (link->Attribute("name", "world") && c.sys.model.floatingBase)
      mujocoError(c.name, "the URDF has a link named world: cannot add the floating base");
    for (const char* tag : {"visual", "collision"})
      for (tinyxml2::XMLElement* g = link->FirstChildElement(tag); g; g = link->FirstChildElement(tag))
        link->DeleteChild(g);
  }
  tinyxml2::XMLElement* mj = doc.NewElement("mujoco");
  tinyxml2::XMLElement* compiler = doc.NewElement("compiler");
  compiler->SetAttribute("fusestatic", "true");
  compiler->SetAttribute("discardvisual", "true");
  compiler->SetAttribute("inertiafromgeom", "false");
  compiler->SetAttribute("balanceinertia", "false");
  mj->InsertEndChild(compiler);
  robot->InsertFirstChild(mj);
  if (c.sys.model.floatingBase) {
    tinyxml2::XMLElement* world = doc.NewElement("link");
    world->SetAttribute("name", "world");
    robot->InsertEndChild(world);
    tinyxml2::XMLElement* joint = doc.NewElement("joint");
    joint->SetAttribute("name", "root_joint");
    joint->SetAttribute("type", "floating");
    joint->InsertNewChildElement("parent")->SetAttribute("link", "world");
    joint->InsertNewChildElement("child")->SetAttribute("link", c.sys.model.bodies[1].link.c_str());
    robot->InsertEndChild(joint);
  }
  tinyxml2::XMLPrinter out;
  doc.Print(&out);
  return out.CStr();
}

// mj_loadXML on text held in memory (a virtual file `name`).
ModelPtr loadFromText(const std::string& caseName, const std::string& name, const std::string& text) {
  auto vfs = std::make_unique<mjVFS>();  // ~2 MB: not on the stack
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), int(text.size())) != 0)
    mujocoError(caseName, "cannot make the virtual file " + name);
  const int idx = mj_findFileVFS(vfs.get(), name.c_str());
  std::memcpy(vfs->filedata[idx], text.data(), text.size());
  char error[1000] = "";
  ModelPtr m(mj_loadXML(name.c_str(), vfs.get(), error, sizeof error));
  mj_deleteVFS(vfs.get());
  if (!m) mujocoError(caseName, "MuJoCo does not load the " + name + ": " + error);
  return m;
}

// The MJCF MuJoCo writes for the model it last loaded.
std::string savedMjcf(const std::string& caseName, const mjModel* m) {
  const char* tmp = std::getenv("TMPDIR");
  std::string path = std::string(tmp && *tmp ? tmp : "/tmp") + "/proxgen-mujoco-XXXXXX";
  const int fd = mkstemp(path.data());
  if (fd < 0) mujocoError(caseName, "cannot create a temporary file for the MJCF");
  close(fd);
  char error[1000] = "";
  const int ok = mj_saveLastXML(path.c_str(), m, error, sizeof error);
  std::string text = readText(path);
  std::remove(path.c_str());
  if (!ok || text.empty()) mujocoError(caseName, std::string("mj_saveLastXML failed: ") + error);
  return text;
}

std::string numbers(std::initializer_list<double> xs) {
  std::ostringstream s;
  s.precision(17);
  const char* sep = "";
  for (double x : xs) {
    s << sep << x;
    sep = " ";
  }
  return s.str();
}

// The layout's constraints as MJCF equalities on the world, in layout order (so
// MuJoCo's rows come in proxgen's order). Their anchors and poses are set again per
// state (MujocoSolver::heldWhereTheyAre).
std::string equalities(const BenchCase& c) {
  std::string out = "  <equality>\n";
  for (const Constraint& k : c.sys.constraints) {
    if (k.kp != 0 || k.kd != 0) mujocoError(c.name, "constraint " + k.name + " has Baumgarte gains: not mapped to MuJoCo");
    const std::string body = c.sys.model.bodies[std::size_t(k.body)].link;
    const Vec3& p = k.placement.p;
    if (k.type == ConstraintType::Point3D) {
      out += "    <connect name=\"" + k.name + "\" body1=\"" + body + "\" anchor=\"" + numbers({p.x(), p.y(), p.z()}) +
             "\"/>\n";
    } else {
      const Eigen::Quaterniond r(k.placement.R);
      out += "    <weld name=\"" + k.name + "\" body1=\"" + body + "\" relpose=\"" +
             numbers({p.x(), p.y(), p.z(), r.w(), r.x(), r.y(), r.z()}) + "\" anchor=\"0 0 0\"/>\n";
    }
  }
  return out + "  </equality>\n";
}

template <class T>
void copyArray(T* to, const T* from, int n) {
  std::copy(from, from + n, to);
}

// The reloaded model (m2) with the URDF-compiled model's (m1) numbers, after checking
// that both have the same tree.
void copyNumbers(const std::string& caseName, const mjModel* m1, mjModel* m2) {
  if (m1->nbody != m2->nbody || m1->njnt != m2->njnt || m1->nq != m2->nq || m1->nv != m2->nv)
    mujocoError(caseName, "the MJCF MuJoCo wrote has another tree than the URDF it read");
  for (int b = 0; b < m1->nbody; ++b)
    if (m1->body_parentid[b] != m2->body_parentid[b] || m1->body_jntnum[b] != m2->body_jntnum[b])
      mujocoError(caseName, "the MJCF MuJoCo wrote has another tree than the URDF it read");
  for (int j = 0; j < m1->njnt; ++j)
    if (m1->jnt_type[j] != m2->jnt_type[j] || m1->jnt_bodyid[j] != m2->jnt_bodyid[j])
      mujocoError(caseName, "the MJCF MuJoCo wrote has other joints than the URDF it read");
  copyArray(m2->body_pos, m1->body_pos, 3 * m1->nbody);
  copyArray(m2->body_quat, m1->body_quat, 4 * m1->nbody);
  copyArray(m2->body_ipos, m1->body_ipos, 3 * m1->nbody);
  copyArray(m2->body_iquat, m1->body_iquat, 4 * m1->nbody);
  copyArray(m2->body_mass, m1->body_mass, m1->nbody);
  copyArray(m2->body_subtreemass, m1->body_subtreemass, m1->nbody);
  copyArray(m2->body_inertia, m1->body_inertia, 3 * m1->nbody);
  copyArray(m2->jnt_pos, m1->jnt_pos, 3 * m1->njnt);
  copyArray(m2->jnt_axis, m1->jnt_axis, 3 * m1->njnt);
  copyArray(m2->dof_armature, m1->dof_armature, m1->nv);
  copyArray(m2->dof_damping, m1->dof_damping, m1->nv);
  copyArray(m2->qpos0, m1->qpos0, m1->nq);
}

// Where each proxgen joint's slots are in MuJoCo's qpos/qvel.
struct Slot {
  JointType type;
  int idx_q, idx_v, nv;  // proxgen
  int qpos, dof;         // MuJoCo
};

std::vector<Slot> jointSlots(const BenchCase& c, const mjModel* m) {
  std::vector<Slot> slots;
  std::vector<int> dofUsed(std::size_t(m->nv), 0);
  for (std::size_t i = 1; i < c.sys.model.bodies.size(); ++i) {
    const Joint& j = c.sys.model.bodies[i].joint;
    const int id = mj_name2id(m, mjOBJ_JOINT, j.name.c_str());
    if (id < 0) mujocoError(c.name, "joint " + j.name + " is not in MuJoCo's model");
    const int want = j.type == JointType::FreeFlyer ? mjJNT_FREE
                     : j.type == JointType::Prismatic ? mjJNT_SLIDE
                     : j.type == JointType::Revolute  ? mjJNT_HINGE
                                                      : -1;
    if (want < 0 || m->jnt_type[id] != want || j.nq != (want == mjJNT_FREE ? 7 : 1))
      mujocoError(c.name, "joint " + j.name + " has another type in MuJoCo (planar and two-slot joints not mapped)");
    const Slot s{j.type, j.idx_q, j.idx_v, j.nv, m->jnt_qposadr[id], m->jnt_dofadr[id]};
    for (int k = 0; k < j.nv; ++k) ++dofUsed[std::size_t(s.dof + k)];
    slots.push_back(s);
  }
  if (m->nv != c.sys.model.nv || std::any_of(dofUsed.begin(), dofUsed.end(), [](int n) { return n != 1; }))
    mujocoError(c.name, "MuJoCo's degrees of freedom do not map one to one onto proxgen's");
  return slots;
}

// proxgen's state in MuJoCo's coordinates. A free flyer: MuJoCo's quaternion is
// scalar first; its linear velocity (and force) is in the world frame, the angular
// one in the body frame; proxgen's twist and force are both in the body frame.
void toMujoco(const std::vector<Slot>& slots, const State& s, double* qpos, double* qvel, double* qfrc) {
  for (const Slot& j : slots) {
    if (j.type != JointType::FreeFlyer) {
      qpos[j.qpos] = s.q[j.idx_q];
      qvel[j.dof] = s.v[j.idx_v];
      qfrc[j.dof] = s.tau[j.idx_v];
      continue;
    }
    const Eigen::Quaterniond quat(s.q[j.idx_q + 6], s.q[j.idx_q + 3], s.q[j.idx_q + 4], s.q[j.idx_q + 5]);
    const Mat3 R = quat.toRotationMatrix();
    for (int k = 0; k < 3; ++k) qpos[j.qpos + k] = s.q[j.idx_q + k];
    qpos[j.qpos + 3] = quat.w(), qpos[j.qpos + 4] = quat.x(), qpos[j.qpos + 5] = quat.y(), qpos[j.qpos + 6] = quat.z();
    const Vec3 v = R * s.v.segment<3>(j.idx_v), f = R * s.tau.segment<3>(j.idx_v);
    for (int k = 0; k < 3; ++k) {
      qvel[j.dof + k] = v[k];
      qvel[j.dof + 3 + k] = s.v[j.idx_v + 3 + k];
      qfrc[j.dof + k] = f[k];
      qfrc[j.dof + 3 + k] = s.tau[j.idx_v + 3 + k];
    }
  }
}

// MuJoCo's qacc as proxgen's qdd. A free flyer's linear qacc is the world
// acceleration of the base origin; proxgen's is the derivative of the body-frame
// linear velocity: R^T pdd - w x v.
VecX fromMujoco(const std::vector<Slot>& slots, const State& s, const double* qacc) {
  VecX qdd(s.v.size());
  for (const Slot& j : slots) {
    if (j.type != JointType::FreeFlyer) {
      qdd[j.idx_v] = qacc[j.dof];
      continue;
    }
    const Eigen::Quaterniond quat(s.q[j.idx_q + 6], s.q[j.idx_q + 3], s.q[j.idx_q + 4], s.q[j.idx_q + 5]);
    const Vec3 pdd(qacc[j.dof], qacc[j.dof + 1], qacc[j.dof + 2]);
    const Vec3 w = s.v.segment<3>(j.idx_v + 3), v = s.v.segment<3>(j.idx_v);
    qdd.segment<3>(j.idx_v) = quat.toRotationMatrix().transpose() * pdd - w.cross(v);
    for (int k = 0; k < 3; ++k) qdd[j.idx_v + 3 + k] = qacc[j.dof + 3 + k];
  }
  return qdd;
}

double relativeGap(const VecX& a, const VecX& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, b.lpNorm<Eigen::Infinity>());
}

class MujocoSolver final : public Solver {
 public:
  explicit MujocoSolver(const BenchCase& c) {
    const std::string urdf = urdfForMujoco(c);
    const ModelPtr fromUrdf = loadFromText(c.name, "robot.urdf", urdf);
    std::string mjcf = savedMjcf(c.name, fromUrdf.get());
    const std::size_t end = mjcf.rfind("</mujoco>");
    if (end == std::string::npos) mujocoError(c.name, "the MJCF MuJoCo wrote has no </mujoco>");
    mjcf.insert(end, equalities(c));
    m_ = loadFromText(c.name, "robot.xml", mjcf);
    copyNumbers(c.name, fromUrdf.get(), m_.get());
    if (m_->neq != int(c.sys.constraints.size())) mujocoError(c.name, "MuJoCo did not take every constraint");
    // Stiff equalities without stabilisation (docs/benchmarks.md, "Peers in the same
    // run"): impedance d at MuJoCo's largest (0.9999) whatever the violation, and
    // solref in its direct form (-stiffness, -damping) = (0, 0), so the reference
    // acceleration is 0, as proxgen's layouts ask (no Baumgarte gains).
    for (int e = 0; e < m_->neq; ++e) {
      m_->eq_solref[mjNREF * e] = 0, m_->eq_solref[mjNREF * e + 1] = 0;
      const double imp[mjNIMP] = {0.9999, 0.9999, 0.001, 0.5, 2};
      std::copy(imp, imp + mjNIMP, m_->eq_solimp + mjNIMP * e);
    }
    // Nothing proxgen's model does not have: no contacts (collision detection off), no
    // joint limits, friction loss or passive forces (the URDFs declare no damping),
    // and each call from scratch, as proxgen's are (no warm start).
    m_->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_LIMIT | mjDSBL_FRICTIONLOSS | mjDSBL_PASSIVE | mjDSBL_WARMSTART;
    for (int k = 0; k < 3; ++k) m_->opt.gravity[k] = c.sys.model.gravity[k];
    d_.reset(mj_makeData(m_.get()));
    mj_setConst(m_.get(), d_.get());
    slots_ = jointSlots(c, m_.get());

    // The pool in MuJoCo's coordinates, converted once outside the timing.
    n_ = int(c.states.size());
    qpos_.resize(std::size_t(n_ * m_->nq));
    qvel_.resize(std::size_t(n_ * m_->nv));
    qfrc_.resize(std::size_t(n_ * m_->nv));
    for (int k = 0; k < n_; ++k)
      toMujoco(slots_, c.states[std::size_t(k)], &qpos_[std::size_t(k * m_->nq)], &qvel_[std::size_t(k * m_->nv)],
               &qfrc_[std::size_t(k * m_->nv)]);
    eqData_.resize(std::size_t(n_ * m_->neq * mjNEQDATA));
    for (int k = 0; k < n_; ++k) heldWhereTheyAre(c, k);
    check(c);
  }

  void solve(int k) override {
    mju_copy(m_->eq_data, &eqData_[std::size_t(k * m_->neq * mjNEQDATA)], m_->neq * mjNEQDATA);
    mju_copy(d_->qpos, &qpos_[std::size_t(k * m_->nq)], m_->nq);
    mju_copy(d_->qvel, &qvel_[std::size_t(k * m_->nv)], m_->nv);
    mju_copy(d_->qfrc_applied, &qfrc_[std::size_t(k * m_->nv)], m_->nv);
    mj_forward(m_.get(), d_.get());
  }
  const void* output() const override { return d_->qacc; }
  std::vector<std::pair<std::string, double>> counters() const override { return counters_; }

 private:
  // MuJoCo's answers against the generic solvers on the first kCheck states:
  // - without constraints, qacc against ABA: the same rigid-body model, so they agree
  //   to round-off unless the model differs (joint order, frames, inertias);
  // - with the constraints, at v = 0 (MuJoCo leaves out the J' v term: its equality
  //   rows ask J qacc = aref, proxgen's J qdd + J' v = 0; they agree only at v = 0),
  //   MuJoCo made exactly a penalty method of weight mu: its regularisation R =
  //   (1 - d)/d * diagApprox set to 1/mu per row (d = 0.9999 and the constrained
  //   bodies' invweight0, which is all diagApprox reads for equalities, set to match;
  //   MuJoCo 2.2.2 gives weld rotation rows the translational one: its mj_diagApprox
  //   compares efc_type with mjEQ_WELD), and weld rotation rows made the angular
  //   velocity's (torquescale 2: at zero error they are half of it). Newton solves
  //   that quadratic in one step, and it is the first
  //   proximal step of proxgen's constrained ABA from lambda = 0 (K = 1), so the two
  //   agree to round-off unless a constraint's body, anchor, frame or row differs.
  // Both bounds are 1e-6 relative to max(1, |qdd|): the systems solved (M, and
  // M + mu J^T J) are SPD with condition numbers up to ~1e8 and ~1e8 * mu |J|^2 /
  // |M| on these robots, solved by backward-stable factorisations in double; the
  // measured gaps (counters mj_free_gap, mj_cons_gap: at most 4e-9) sit orders below,
  // and a wrong inertia or anchor moves qdd by far more (on iiwa_h3: 1 % more mass on
  // the last body, 5e-3; the contact point 1 mm off, 0.26).
  void check(const BenchCase& c) {
    constexpr int kCheck = 20;
    Data gd(c.sys);
    double freeGap = 0, consGap = 0;
    const int saved = m_->opt.disableflags;
    std::vector<double> invweight(m_->body_invweight0, m_->body_invweight0 + 2 * m_->nbody);
    std::vector<double> solimp(m_->eq_solimp, m_->eq_solimp + mjNIMP * m_->neq);
    const double d = 0.9999, rowWeight = d / (1 - d) / kMu;  // R = (1-d)/d * w = 1/mu
    for (int e = 0; e < m_->neq; ++e) {
      const int b = m_->eq_obj1id[e];
      m_->body_invweight0[2 * b] = rowWeight;
      m_->body_invweight0[2 * b + 1] = rowWeight;
      m_->eq_solimp[mjNIMP * e] = m_->eq_solimp[mjNIMP * e + 1] = d;
    }
    for (int k = 0; k < std::min(kCheck, n_); ++k) {
      const State& s = c.states[std::size_t(k)];
      m_->opt.disableflags = saved | mjDSBL_CONSTRAINT;
      solve(k);
      freeGap = std::max(freeGap, relativeGap(fromMujoco(slots_, s, d_->qacc), aba(c.sys, gd, s.q, s.v, s.tau)));
      m_->opt.disableflags = saved;
      State still = s;
      still.v.setZero();
      std::vector<double> qpos(std::size_t(m_->nq)), qvel(std::size_t(m_->nv)), qfrc(std::size_t(m_->nv));
      toMujoco(slots_, still, qpos.data(), qvel.data(), qfrc.data());
      mju_copy(m_->eq_data, &eqData_[std::size_t(k * m_->neq * mjNEQDATA)], m_->neq * mjNEQDATA);
      for (int e = 0; e < m_->neq; ++e)
        if (m_->eq_type[e] == mjEQ_WELD) m_->eq_data[mjNEQDATA * e + 10] = 2;  // torquescale
      mju_copy(d_->qpos, qpos.data(), m_->nq);
      mju_copy(d_->qvel, qvel.data(), m_->nv);
      mju_copy(d_->qfrc_applied, qfrc.data(), m_->nv);
      mj_forward(m_.get(), d_.get());
      constrainedAba(c.sys, gd, still.q, still.v, still.tau, kMu, 1);
      consGap = std::max(consGap, relativeGap(fromMujoco(slots_, still, d_->qacc), gd.qdd));
    }
    std::copy(invweight.begin(), invweight.end(), m_->body_invweight0);
    std::copy(solimp.begin(), solimp.end(), m_->eq_solimp);
    if (!(freeGap <= 1e-6))
      mujocoError(c.name, "without constraints MuJoCo's qacc differs from ABA's qdd by " + std::to_string(freeGap) +
                              " (relative): the two models differ");
    if (!(consGap <= 1e-6))
      mujocoError(c.name, "as a penalty method MuJoCo's qacc differs from constrained ABA's (K = 1) by " +
                              std::to_string(consGap) + " (relative): the constraints differ");
    // MuJoCo's solver effort on the whole pool (Newton by default: one step solves the
    // quadratic problem of equalities alone; the count is of steps taken).
    double iterations = 0;
    int most = 0;
    for (int k = 0; k < n_; ++k) {
      solve(k);
      iterations += d_->solver_iter;
      most = std::max(most, d_->solver_iter);
    }
    counters_ = {{"mj_free_gap", freeGap},
                 {"mj_cons_gap", consGap},
                 {"mj_iter_mean", iterations / n_},
                 {"mj_iter_max", most},
                 {"mj_nefc", d_->nefc},
                 {"mj_version", mj_version()}};
  }

  // The equalities of state k hold the constraint frames where that state puts them
  // (zero position and orientation error), stored for solve(). proxgen's constraints
  // (no Baumgarte gains) have no position target, only J qdd + J' v = 0; MuJoCo's
  // weld rows are the quaternion error's derivative, which equals the frame's angular
  // velocity rows only at zero error (at a large one they are scaled by its scalar
  // part, and with them the softness relative to the rows), hence the per-state pose.
  // connect: data = [anchor in body1, the same point in the world]; weld (MuJoCo
  // 2.2.2's layout): [anchor in the world, relpose pos in body1, relpose quat
  // (w x y z), torquescale].
  void heldWhereTheyAre(const BenchCase& c, int k) {
    mju_copy(d_->qpos, &qpos_[std::size_t(k * m_->nq)], m_->nq);
    mj_kinematics(m_.get(), d_.get());
    double* data = &eqData_[std::size_t(k * m_->neq * mjNEQDATA)];
    mju_copy(data, m_->eq_data, m_->neq * mjNEQDATA);
    for (int e = 0; e < m_->neq; ++e, data += mjNEQDATA) {
      const Constraint& con = c.sys.constraints[std::size_t(e)];
      const int b = m_->eq_obj1id[e];
      double world[3];
      mju_rotVecMat(world, con.placement.p.data(), d_->xmat + 9 * b);
      mju_addTo3(world, d_->xpos + 3 * b);
      if (con.type == ConstraintType::Point3D) {
        mju_copy3(data, con.placement.p.data());
        mju_copy3(data + 3, world);
      } else {
        mju_copy3(data, world);
        mju_copy3(data + 3, con.placement.p.data());
        mju_negQuat(data + 6, d_->xquat + 4 * b);
        data[10] = 1;
      }
    }
  }

  ModelPtr m_;
  DataPtr d_;
  std::vector<Slot> slots_;
  int n_ = 0;
  std::vector<double> qpos_, qvel_, qfrc_, eqData_;
  std::vector<std::pair<std::string, double>> counters_;
};

}  // namespace

std::unique_ptr<Solver> makeMujocoSolver(const BenchCase& c) { return std::make_unique<MujocoSolver>(c); }

}  // namespace proxgen::bench
