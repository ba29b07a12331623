// Pinocchio (3.7 or later, where CMake finds an install: bench/pinocchio.cmake) on
// the shared cases, timed by the suite as "pin_caba" (pinocchio::constrainedABA) and
// "pin_pv" (pinocchio::pv), the two algorithms of the anchor figures
// (docs/benchmarks.md, "Anchor figures", "Peers in the same run"). Per case: the
// case's URDF through Pinocchio's own parser (a free flyer root_joint for a floating
// base), one RigidConstraintModel per layout constraint (CONTACT_6D / CONTACT_3D on
// the link's parent joint at the link frame times the layout offset, LOCAL, as the
// layout's constraints are), and the case's state pool as is: proxgen's conventions
// are Pinocchio's (docs/design.md, "Conventions"), which the constructor checks
// joint by joint and with Pinocchio's ABA against proxgen's on the case's states.
//
// pinocchioJointSpace: Pinocchio's rnea, nonLinearEffects, crba and
// computeMinverse on bench_joint_space.cpp's states, as the "pinocchio" variants
// beside the generated joint-space functions (docs/benchmarks.md, "The dynamics
// library"). crba and computeMinverse fill only the upper triangle; the
// "pinocchio" variant also copies it to the lower one (what the generated
// functions return: the full matrix), "pinocchio_upper" is the call alone.
//
// makePinocchioConstraintDerivatives: pinocchio::constraintDynamics followed by
// computeConstraintDynamicsDerivatives with the same constraint models, for
// bench_derivatives.cpp (bench_pinocchio.hpp), on that executable's states;
// compiled only with PROXGEN_BENCH_PINOCCHIO_DERIVATIVES (bench/derivatives.cmake
// defines it for proxgen_bench_derivatives alone): with the derivative templates
// this file took 524 s to compile (GCC 12, -O3, wall, load ~2.5 on 2 cores; without
// them its -fsyntax-only alone takes 166 s), a difference the suite's and the
// library's builds, which do not call them, need not pay.
//
// Settings: mu = 1/kMu (Pinocchio's mu is the inverse of proxgen's), max_iter = K =
// kIterations and accuracy 0, so no call stops before its K-th iteration.
// Pinocchio 3.7 marks the constraint models, pv, constrainedABA and initPvSolver
// "unsupported" (their API may change) through its deprecation attribute, in its own
// headers too: the warning says nothing about this use.
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#include <pinocchio/algorithm/aba.hpp>
#ifdef PROXGEN_BENCH_PINOCCHIO_DERIVATIVES
#include <pinocchio/algorithm/constrained-dynamics-derivatives.hpp>
#include <pinocchio/algorithm/constrained-dynamics.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#endif
#include <pinocchio/algorithm/contact-info.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/proximal.hpp>
#include <pinocchio/algorithm/pv.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <algorithm>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/aba.hpp"
#include "algorithms/crba.hpp"
#include "algorithms/data.hpp"
#include "algorithms/mass_matrix_inverse.hpp"
#include "algorithms/rnea.hpp"
#include "bench_pinocchio.hpp"
#include "common.hpp"
#include "model/error.hpp"

namespace proxgen::bench {
namespace {

using ConstraintModels = PINOCCHIO_STD_VECTOR_WITH_EIGEN_ALLOCATOR(pinocchio::RigidConstraintModel);
using ConstraintDatas = PINOCCHIO_STD_VECTOR_WITH_EIGEN_ALLOCATOR(pinocchio::RigidConstraintData);

[[noreturn]] void pinocchioError(const std::string& caseName, const std::string& what) {
  throw Error("pinocchio, case " + caseName + ": " + what);
}

pinocchio::SE3 toPinocchio(const SE3& x) { return pinocchio::SE3(x.R, x.p); }

enum class Algorithm { Caba, Pv };

// The case's URDF through Pinocchio's parser, checked joint by joint against proxgen's slots.
void buildPinocchioModel(const std::string& caseName, const Model& pm, pinocchio::Model& model) {
  if (pm.floatingBase)
    pinocchio::urdf::buildModel(pm.sourcePath, pinocchio::JointModelFreeFlyer(), model);
  else
    pinocchio::urdf::buildModel(pm.sourcePath, model);
  if (model.nq != pm.nq || model.nv != pm.nv) pinocchioError(caseName, "Pinocchio's nq, nv differ from proxgen's");
  // The same joints in the same slots (joint 0 is Pinocchio's universe).
  for (std::size_t i = 1; i < pm.bodies.size(); ++i) {
    const Joint& j = pm.bodies[i].joint;
    if (!model.existJointName(j.name)) pinocchioError(caseName, "joint " + j.name + " is not in Pinocchio's model");
    const pinocchio::JointIndex id = model.getJointId(j.name);
    if (model.idx_qs[id] != j.idx_q || model.idx_vs[id] != j.idx_v || model.nqs[id] != j.nq ||
        model.nvs[id] != j.nv)
      pinocchioError(caseName, "joint " + j.name + " has other slots in Pinocchio's model");
  }
}

// One RigidConstraintModel per layout constraint (and its data), in layout order.
void buildConstraintModels(const std::string& caseName, const System& sys, const pinocchio::Model& model,
                           ConstraintModels& models, ConstraintDatas& datas) {
  for (const Constraint& k : sys.constraints) {
    if (k.kp != 0 || k.kd != 0)
      pinocchioError(caseName, "constraint " + k.name + " has Baumgarte gains (Pinocchio's pv does not honour kp)");
    if (!model.existFrame(k.link, pinocchio::BODY)) pinocchioError(caseName, "no body frame " + k.link);
    const pinocchio::Frame& f = model.frames[model.getFrameId(k.link, pinocchio::BODY)];
    const pinocchio::ContactType type = k.type == ConstraintType::Weld6D ? pinocchio::CONTACT_6D : pinocchio::CONTACT_3D;
    models.emplace_back(type, model, f.parentJoint, f.placement * toPinocchio(k.offset), pinocchio::LOCAL);
  }
  for (const auto& m : models) datas.emplace_back(m);
}

class PinocchioSolver final : public Solver {
 public:
  PinocchioSolver(const BenchCase& c, Algorithm algorithm)
      : states_(c.states), algorithm_(algorithm), settings_(0.0, 1.0 / kMu, kIterations) {
    buildPinocchioModel(c.name, c.sys.model, model_);
    buildConstraintModels(c.name, c.sys, model_, models_, datas_);
    data_ = std::make_unique<pinocchio::Data>(model_);
    pinocchio::initPvSolver(model_, *data_, models_);

    // Same dynamics model: Pinocchio's ABA against proxgen's on the first states, to
    // round-off (both are the same recursion in double on the same numbers; 1e-9
    // relative to max(1, |qdd|) leaves orders of margin over eps * cond(M)).
    Data gd(c.sys);
    double gap = 0;
    for (std::size_t k = 0; k < std::min<std::size_t>(20, states_.size()); ++k) {
      const State& s = states_[k];
      const VecX& mine = aba(c.sys, gd, s.q, s.v, s.tau);
      const Eigen::VectorXd theirs = pinocchio::aba(model_, *data_, s.q, s.v, s.tau);
      gap = std::max(gap, (theirs - mine).lpNorm<Eigen::Infinity>() / std::max(1.0, mine.lpNorm<Eigen::Infinity>()));
    }
    if (!(gap <= 1e-9))
      pinocchioError(c.name, "Pinocchio's ABA differs from proxgen's by " + std::to_string(gap) + " (relative)");
    counters_ = {{"pin_aba_gap", gap}};
  }

  void solve(int k) override {
    const State& s = states_[std::size_t(k)];
    if (algorithm_ == Algorithm::Caba)
      pinocchio::constrainedABA(model_, *data_, s.q, s.v, s.tau, models_, datas_, settings_);
    else
      pinocchio::pv(model_, *data_, s.q, s.v, s.tau, models_, datas_, settings_);
  }
  const void* output() const override { return data_->ddq.data(); }
  std::vector<std::pair<std::string, double>> counters() const override { return counters_; }

 private:
  const std::vector<State>& states_;
  Algorithm algorithm_;
  pinocchio::Model model_;
  std::unique_ptr<pinocchio::Data> data_;
  ConstraintModels models_;
  ConstraintDatas datas_;
  pinocchio::ProximalSettings settings_;
  std::vector<std::pair<std::string, double>> counters_;
};

#ifdef PROXGEN_BENCH_PINOCCHIO_DERIVATIVES
// constraintDynamics + computeConstraintDynamicsDerivatives (bench_pinocchio.hpp).
// Pinocchio's multipliers are the forces on the robot, M qdd + h = tau + J^T
// lambda_pin (its KKT solve returns -lambda_pin): lambda = -lambda_pin in
// proxgen's convention, and so for their tangents. settings_ is one object for
// both calls: constraintDynamics writes settings.iter, the derivatives run that
// many proximal steps on the tangents.
class PinocchioDerivatives final : public PinocchioConstraintDerivatives {
 public:
  PinocchioDerivatives(const std::string& caseName, const System& sys, const std::vector<State>& states, double mu,
                       int K)
      : states_(states), settings_(0.0, 1.0 / mu, K) {
    buildPinocchioModel(caseName, sys.model, model_);
    buildConstraintModels(caseName, sys, model_, models_, datas_);
    data_ = std::make_unique<pinocchio::Data>(model_);
    pinocchio::initConstraintDynamics(model_, *data_, models_);
  }
  void call(int k) override {
    const State& s = states_[std::size_t(k)];
    pinocchio::constraintDynamics(model_, *data_, s.q, s.v, s.tau, models_, datas_, settings_);
    pinocchio::computeConstraintDynamicsDerivatives(model_, *data_, models_, datas_, settings_);
  }
  void read(ConstrainedDerivatives& out) const override {
    out.qdd = data_->ddq;
    out.lambda = -data_->lambda_c;
    out.dqdd_dq = data_->ddq_dq, out.dqdd_dv = data_->ddq_dv, out.dqdd_dtau = data_->ddq_dtau;
    out.dlambda_dq = -data_->dlambda_dq, out.dlambda_dv = -data_->dlambda_dv, out.dlambda_dtau = -data_->dlambda_dtau;
  }
  int iterations() const override { return settings_.iter; }

 private:
  const std::vector<State>& states_;
  pinocchio::Model model_;
  std::unique_ptr<pinocchio::Data> data_;
  ConstraintModels models_;
  ConstraintDatas datas_;
  pinocchio::ProximalSettings settings_;
};

// computeRNEADerivatives (bench_pinocchio.hpp). Its five-argument form writes
// data.dtau_dq, data.dtau_dv and data.M, zeroed once by Data's constructor: each
// call writes the same entries again (their pattern is the model's), as its
// documentation asks of the zeros.
class PinocchioRnea final : public PinocchioRneaDerivatives {
 public:
  PinocchioRnea(const std::string& caseName, const System& sys, const std::vector<State>& states)
      : states_(states) {
    buildPinocchioModel(caseName, sys.model, model_);
    data_ = std::make_unique<pinocchio::Data>(model_);
  }
  void call(int k) override {
    const State& s = states_[std::size_t(k)];
    pinocchio::computeRNEADerivatives(model_, *data_, s.q, s.v, s.tau);
  }
  void read(MatX& dtau_dq, MatX& dtau_dv) const override {
    dtau_dq = data_->dtau_dq;
    dtau_dv = data_->dtau_dv;
  }

 private:
  const std::vector<State>& states_;
  pinocchio::Model model_;
  std::unique_ptr<pinocchio::Data> data_;
};

}  // namespace

std::unique_ptr<PinocchioRneaDerivatives> makePinocchioRneaDerivatives(const std::string& caseName,
                                                                       const System& sys,
                                                                       const std::vector<State>& states) {
  return std::make_unique<PinocchioRnea>(caseName, sys, states);
}

std::unique_ptr<PinocchioConstraintDerivatives> makePinocchioConstraintDerivatives(const std::string& caseName,
                                                                                   const System& sys,
                                                                                   const std::vector<State>& states,
                                                                                   double mu, int K) {
  return std::make_unique<PinocchioDerivatives>(caseName, sys, states, mu, K);
}
#else
}  // namespace
#endif

std::unique_ptr<Solver> makePinocchioCaba(const BenchCase& c) {
  return std::make_unique<PinocchioSolver>(c, Algorithm::Caba);
}
std::unique_ptr<Solver> makePinocchioPv(const BenchCase& c) {
  return std::make_unique<PinocchioSolver>(c, Algorithm::Pv);
}

namespace {

// One case's Pinocchio model and data for the joint-space functions.
struct JointSpaceModel {
  pinocchio::Model model;
  std::unique_ptr<pinocchio::Data> data;
};

// The largest |a - b| / max(1, |b|) over the first states, between Pinocchio's
// function and proxgen's generic one (both in double on the same inputs).
template <class Theirs, class Mine>
double gapOver(const std::vector<State>& states, Theirs theirs, Mine mine) {
  double gap = 0;
  for (std::size_t k = 0; k < std::min<std::size_t>(20, states.size()); ++k) {
    const MatX a = theirs(k), b = mine(k);
    gap = std::max(gap, (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, b.lpNorm<Eigen::Infinity>()));
  }
  return gap;
}

// The lower triangle from the upper one (Pinocchio's idiom, no aliasing: each side reads only the other).
template <class M>
void symmetrize(M& upper) {
  upper.template triangularView<Eigen::StrictlyLower>() =
      upper.transpose().template triangularView<Eigen::StrictlyLower>();
}

}  // namespace

std::function<void(int)> pinocchioJointSpace(const std::string& caseName, const System& sys,
                                             const std::vector<State>& states, const std::vector<VecX>& qdd,
                                             const std::string& function) {
  const auto js = std::make_shared<JointSpaceModel>();
  buildPinocchioModel(caseName, sys.model, js->model);
  js->data = std::make_unique<pinocchio::Data>(js->model);
  pinocchio::Model& model = js->model;
  pinocchio::Data& data = *js->data;
  Data gd(sys);
  // Same function on the same inputs before any timing: Pinocchio's against the
  // generic twin, to round-off: 1e-9 relative to max(1, |ours|), as the suite's ABA
  // check (both are the same recursions in double on the same numbers; the
  // constructor throws if a case misses it, and none of the shared cases does).
  double gap = 0;
  std::function<void(int)> call;
  if (function == "inverse_dynamics") {
    gap = gapOver(
        states, [&](std::size_t k) -> MatX { return pinocchio::rnea(model, data, states[k].q, states[k].v, qdd[k]); },
        [&](std::size_t k) -> MatX { return rnea(sys, gd, states[k].q, states[k].v, qdd[k]); });
    call = [js, &states, &qdd](int k) {
      const State& s = states[std::size_t(k)];
      pinocchio::rnea(js->model, *js->data, s.q, s.v, qdd[std::size_t(k)]);
    };
  } else if (function == "nonlinear_effects") {
    gap = gapOver(
        states,
        [&](std::size_t k) -> MatX { return pinocchio::nonLinearEffects(model, data, states[k].q, states[k].v); },
        [&](std::size_t k) -> MatX { return nonLinearEffects(sys, gd, states[k].q, states[k].v); });
    call = [js, &states](int k) {
      const State& s = states[std::size_t(k)];
      pinocchio::nonLinearEffects(js->model, *js->data, s.q, s.v);
    };
  } else if (function == "mass_matrix" || function == "mass_matrix_upper" || function == "mass_matrix_world") {
    // Pinocchio 3.7's crba has two conventions: LOCAL (its default, Featherstone's
    // recursion in the joint frames) and WORLD (the columns of M from world-frame
    // Jacobians and composite inertias). Both are timed so that the comparison is
    // against Pinocchio's faster one: measured here, LOCAL (docs/benchmarks.md).
    const pinocchio::Convention convention =
        function == "mass_matrix_world" ? pinocchio::Convention::WORLD : pinocchio::Convention::LOCAL;
    gap = gapOver(
        states,
        [&](std::size_t k) -> MatX {
          MatX M = pinocchio::crba(model, data, states[k].q, convention);
          symmetrize(M);
          return M;
        },
        [&](std::size_t k) -> MatX { return crba(sys, gd, states[k].q); });
    if (function == "mass_matrix_upper")
      call = [js, &states](int k) { pinocchio::crba(js->model, *js->data, states[std::size_t(k)].q); };
    else
      call = [js, &states, convention](int k) {
        pinocchio::crba(js->model, *js->data, states[std::size_t(k)].q, convention);
        symmetrize(js->data->M);
      };
  } else if (function == "mass_matrix_inverse" || function == "mass_matrix_inverse_upper") {
    gap = gapOver(
        states,
        [&](std::size_t k) -> MatX {
          MatX Minv = pinocchio::computeMinverse(model, data, states[k].q);
          symmetrize(Minv);
          return Minv;
        },
        [&](std::size_t k) -> MatX { return massMatrixInverse(sys, gd, states[k].q); });
    if (function == "mass_matrix_inverse")
      call = [js, &states](int k) {
        pinocchio::computeMinverse(js->model, *js->data, states[std::size_t(k)].q);
        symmetrize(js->data->Minv);
      };
    else
      call = [js, &states](int k) { pinocchio::computeMinverse(js->model, *js->data, states[std::size_t(k)].q); };
  } else {
    pinocchioError(caseName, "no joint-space function " + function);
  }
  if (!(gap <= 1e-9))
    pinocchioError(caseName, function + ": Pinocchio differs from proxgen's generic twin by " + std::to_string(gap) +
                                 " (relative)");
  return call;
}

}  // namespace proxgen::bench
