#include "emit/c_api.hpp"

#include <fmt/format.h>

#include <vector>

#include "emit/identifiers.hpp"

namespace proxgen::emit {
namespace {

const char* const kCHeaderTemplate =
#include "../../templates/solver_c.h.tpl"
    ;
const char* const kCSourceTemplate =
#include "../../templates/solver_c.cpp.tpl"
    ;

// What a wrapper puts into the Settings it passes: none, the active flags alone
// (passed on as s.active: the constraint functions), mu and the flags
// (delassus_inverse), or everything a solve reads.
enum class SettingsFrom { None, Active, MuActive, Solve };

// One C twin: its parameters after the prefix ("{S}": the scalar), the C++
// call ("w": the Workspace, "s": the Settings) and its comment in the header.
struct CEntry {
  Function f;
  const char* params;
  const char* call;
  SettingsFrom settings;
  const char* comment;
};

const CEntry kCEntries[] = {
    {Function::ConstrainedAba,
     "const {S}* q, const {S}* v, const {S}* tau, {S} mu, int iterations,\n"
     "    const unsigned char* active, const {S}* lambda0, void* work, {S}* qdd, {S}* lambda",
     "constrained_aba(q, v, tau, s, w, qdd, lambda)", SettingsFrom::Solve,
     "/* The solvers, as {name}::constrained_aba / prox_pv with the Settings mu,\n"
     "   iterations, active and lambda0: in q[NQ], v[NV], tau[NV]; active: NCONS\n"
     "   flags (non-zero: the constraint is in force; NULL: all are), in layout\n"
     "   order ({P}_CONSTRAINT_<name>); lambda0: NC multipliers to start the K =\n"
     "   iterations updates from (the previous step's lambda; it may be the lambda\n"
     "   output) or NULL for zero. Out qdd[NV], lambda[NC] (layout order).\n"
     "   Sign: the constraint force on the robot is -J^T lambda (M qdd + h = tau -\n"
     "   J^T lambda): a contact force on the robot, in a library where it enters\n"
     "   as +J^T f, is -lambda ({P}_constraint_wrenches, when held, gives each\n"
     "   constraint's as a world-frame wrench on the robot). */\n"},
    {Function::ProxPv,
     "const {S}* q, const {S}* v, const {S}* tau, {S} mu, int iterations,\n"
     "    const unsigned char* active, const {S}* lambda0, void* work, {S}* qdd, {S}* lambda",
     "prox_pv(q, v, tau, s, w, qdd, lambda)", SettingsFrom::Solve, ""},
    {Function::InverseDynamics,
     "const {S}* q, const {S}* v, const {S}* qdd, const {S}* lambda, const unsigned char* active, void* work, {S}* tau",
     "inverse_dynamics(q, v, qdd, lambda, w, tau, s.active)", SettingsFrom::Active,
     "/* tau[NV] = M qdd + h + J^T lambda; lambda (NC) may be NULL (none); the rows\n"
     "   of inactive constraints (active as the solvers') are not read. */\n"},
    {Function::NonlinearEffects, "const {S}* q, const {S}* v, void* work, {S}* h", "nonlinear_effects(q, v, w, h)",
     SettingsFrom::None, "/* h[NV] = inverse dynamics at qdd = 0 without constraint forces. */\n"},
    {Function::MassMatrix, "const {S}* q, void* work, {S}* M", "mass_matrix(q, w, M)", SettingsFrom::None,
     "/* M[NV * NV], row-major. */\n"},
    {Function::MassMatrixInverse, "const {S}* q, void* work, {S}* Minv", "mass_matrix_inverse(q, w, Minv)",
     SettingsFrom::None, "/* M^-1[NV * NV], row-major. */\n"},
    {Function::ConstraintPlacements, "const {S}* q, void* work, {S}* X", "constraint_placements(q, w, X)",
     SettingsFrom::None,
     "/* X[12 * NCONS]: per constraint its frame's rotation in the world (3 x 3,\n"
     "   row-major), then its origin. */\n"},
    {Function::ConstraintJacobian, "const {S}* q, const unsigned char* active, void* work, {S}* J",
     "constraint_jacobian(q, w, J, s.active)", SettingsFrom::Active,
     "/* J[NC * NV], row-major, in the constraint frames' rows; an inactive\n"
     "   constraint's rows (active as the solvers') are 0. */\n"},
    {Function::ConstraintDrift, "const {S}* q, const {S}* v, const unsigned char* active, void* work, {S}* gamma",
     "constraint_drift(q, v, w, gamma, s.active)", SettingsFrom::Active,
     "/* gamma[NC]: J qdd + gamma is the rows' acceleration (inactive rows 0). */\n"},
    {Function::Delassus, "const {S}* q, const unsigned char* active, void* work, {S}* G", "delassus(q, w, G, s.active)",
     SettingsFrom::Active, "/* G[NC * NC] = J M^-1 J^T, row-major (inactive rows and columns 0). */\n"},
    {Function::DelassusInverse, "const {S}* q, {S} mu, const unsigned char* active, void* work, {S}* Ginv",
     "delassus_inverse(q, s, w, Ginv)", SettingsFrom::MuActive,
     "/* Ginv[NC * NC] = (G + I / mu)^-1, row-major; active as the solvers'. */\n"},
    {Function::ConstraintWrenches, "const {S}* q, const {S}* lambda, void* work, {S}* W",
     "constraint_wrenches(q, lambda, w, W)", SettingsFrom::None,
     "/* W[6 * NCONS]: per constraint the wrench of lambda (NC, a solver's output)\n"
     "   ON THE ROBOT in world axes, force then torque about the constraint\n"
     "   frame's origin: -R [lambda_lin; lambda_ang] (a 3d point: [-R lambda; 0]),\n"
     "   the solvers' sign; the robot pushes its contact with minus these. */\n"},
    {Function::InverseDynamicsDerivatives,
     "const {S}* q, const {S}* v, const {S}* qdd, const {S}* lambda, void* work, {S}* dtau_dq, {S}* dtau_dv",
     "inverse_dynamics_derivatives(q, v, qdd, lambda, w, dtau_dq, dtau_dv)", SettingsFrom::None,
     "/* dtau_dq[NV * NV], dtau_dv[NV * NV], row-major, of tau = M qdd + h + J^T lambda at\n"
     "   fixed qdd, lambda (NULL: none); column k of d/dq is along q (+) t e_k (the\n"
     "   header's tangent convention). */\n"},
    {Function::ForwardDynamicsDerivatives,
     "const {S}* q, const {S}* v, const {S}* tau, void* work, {S}* qdd, {S}* dqdd_dq, {S}* dqdd_dv,\n"
     "    {S}* dqdd_dtau",
     "forward_dynamics_derivatives(q, v, tau, w, qdd, dqdd_dq, dqdd_dv, dqdd_dtau)", SettingsFrom::None,
     "/* qdd[NV] of the unconstrained dynamics and dqdd_dq, dqdd_dv, dqdd_dtau\n"
     "   (NV * NV each, row-major). */\n"},
    {Function::ConstrainedDynamicsDerivatives,
     "const {S}* q, const {S}* v, const {S}* tau, {S} mu, int iterations,\n"
     "    const unsigned char* active, const {S}* lambda0, void* work, {S}* qdd, {S}* lambda, {S}* dqdd_dq,\n"
     "    {S}* dqdd_dv, {S}* dqdd_dtau, {S}* dlambda_dq, {S}* dlambda_dv, {S}* dlambda_dtau",
     "constrained_dynamics_derivatives(q, v, tau, s, w, qdd, lambda, dqdd_dq, dqdd_dv, dqdd_dtau, dlambda_dq, "
     "dlambda_dv, dlambda_dtau)",
     SettingsFrom::Solve,
     "/* qdd[NV], lambda[NC] as {P}_prox_pv with these settings, and the derivatives\n"
     "   of the solution it converges to: dqdd_dq, dqdd_dv, dqdd_dtau (NV * NV each)\n"
     "   and dlambda_dq, dlambda_dv, dlambda_dtau (NC * NV each), row-major; column k\n"
     "   of d/dq is along q (+) t e_k (the header's tangent convention). */\n"},
};

// Every C name a prefix makes that does not depend on the function list.
std::vector<std::string> cNames(const Plan& plan, const std::string& prefix) {
  std::vector<std::string> out;
  for (const char* s : {"NQ", "NV", "NC", "NCONS", "WORK_SIZE", "WORK_ALIGN", "work_size", "work_align", "residual"})
    out.push_back(prefix + "_" + s);
  for (Function f : allFunctions()) out.push_back(prefix + "_" + functionName(f));
  for (const ConstraintPlan& c : plan.constraints) {
    out.push_back(prefix + "_CONSTRAINT_" + c.ident);
    out.push_back(prefix + "_ROW_" + c.ident);
  }
  return out;
}

std::string scalarName(ScalarType t) { return t == ScalarType::Float ? "float" : "double"; }

std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
  return s;
}

}  // namespace

std::string cPrefix(const Plan& plan) {
  for (const std::string& id : cNames(plan, plan.name))
    if (isReservedIdentifier(id)) return "kw_" + plan.name;
  return plan.name;
}

CInterfaceFiles emitCInterface(const Plan& plan, const FunctionSet& functions, const std::string& banner,
                               int workspaceBytes) {
  const std::string prefix = cPrefix(plan), S = scalarName(plan.scalar), name = plan.name;
  const auto fill = [&](const std::string& text) {
    return replaceAll(replaceAll(replaceAll(text, "{S}", S), "{P}", prefix), "{name}", name);
  };

  std::string constraints;
  if (!plan.constraints.empty()) constraints += "\n/* Constraints, layout order: index (active[], W) and first row (lambda). */\n";
  for (std::size_t k = 0; k < plan.constraints.size(); ++k) {
    const ConstraintPlan& c = plan.constraints[k];
    constraints += fmt::format("#define {}_CONSTRAINT_{} {} /* '{}' ({}) */\n#define {}_ROW_{} {}\n", prefix, c.ident, k,
                               escapeComment(c.name), c.weld ? "6d weld, 6 rows" : "3d point, 3 rows", prefix, c.ident,
                               c.row);
  }

  bool withSettings = false;
  std::string declarations, definitions;
  for (const CEntry& ce : kCEntries) {
    if (!functions.has(ce.f)) continue;
    const std::string head = fmt::format("void {}_{}({})", prefix, functionName(ce.f), fill(ce.params));
    // prox_pv alone takes constrained_aba's comment
    const char* comment =
        ce.f == Function::ProxPv && !functions.has(Function::ConstrainedAba) ? kCEntries[0].comment : ce.comment;
    declarations += fmt::format("\n{}{} PROXGEN_C_NOEXCEPT;\n", fill(comment), head);
    std::string body = fmt::format("  {}::Workspace& w = workspaceIn(work);\n", name);
    if (ce.settings == SettingsFrom::Solve)
      body += fmt::format("  const {0}::Settings s = settingsOf(mu, iterations, active, lambda0);\n", name);
    if (ce.settings == SettingsFrom::Active)
      body += fmt::format("  const {0}::Settings s = settingsOf({0}::Settings{{}}.mu, {0}::Settings{{}}.iterations, active, nullptr);\n", name);
    if (ce.settings == SettingsFrom::MuActive)
      body += fmt::format("  const {0}::Settings s = settingsOf(mu, {0}::Settings{{}}.iterations, active, nullptr);\n", name);
    withSettings |= ce.settings != SettingsFrom::None;
    definitions += fmt::format("\n{} noexcept {{\n{}  {}::{};\n}}\n", head, body, name, ce.call);
  }
  if (functions.has(Function::ConstrainedAba) || functions.has(Function::ProxPv)) {
    declarations += fmt::format(
        "\n/* ||J qdd + gamma - a*||_inf of the last solve with this buffer ({}::residual). */\n"
        "{} {}_residual(const void* work) PROXGEN_C_NOEXCEPT;\n",
        name, S, prefix);
    definitions += fmt::format(
        "\n{0} {1}_residual(const void* work) noexcept {{\n"
        "  return {2}::residual(*std::launder(static_cast<const {2}::Workspace*>(work)));\n}}\n",
        S, prefix, name);
  }
  const std::string helpers =
      withSettings ? fmt::format(
                         "\n// active == nullptr: every constraint in force; lambda0 passes through (nullptr: zero).\n"
                         "{0}::Settings settingsOf({1} mu, int iterations, const unsigned char* active, const {1}* lambda0) "
                         "noexcept {{\n"
                         "  {0}::Settings s;\n"
                         "  s.mu = mu;\n"
                         "  s.iterations = iterations;\n"
                         "  for (int k = 0; k < {0}::ncons; ++k) s.active[k] = active == nullptr || active[k] != 0;\n"
                         "  s.lambda0 = lambda0;\n"
                         "  return s;\n"
                         "}}\n",
                         name, S)
                   : "";

  CInterfaceFiles files;
  files.headerName = name + "_c.h";
  files.sourceName = name + "_c.cpp";
  // The Workspace holds only Scalar arrays: its size, and the Scalar's size as
  // an alignment that suffices on every ABI (the source checks both; an empty
  // Workspace is one byte).
  const int align = workspaceBytes == 0 ? 1 : plan.scalar == ScalarType::Float ? 4 : 8;
  const int bytes = workspaceBytes == 0 ? 1 : workspaceBytes;
  files.header = fmt::format(fmt::runtime(kCHeaderTemplate), fmt::arg("banner", banner), fmt::arg("name", name),
                             fmt::arg("prefix", prefix), fmt::arg("scalar", S), fmt::arg("guard", "PROXGEN_C_H_" + prefix),
                             fmt::arg("nq", plan.nq), fmt::arg("nv", plan.nv), fmt::arg("nc", plan.nc),
                             fmt::arg("ncons", plan.constraints.size()), fmt::arg("work_size", bytes),
                             fmt::arg("work_align", align), fmt::arg("constraints", constraints),
                             fmt::arg("declarations", declarations));
  files.source = fmt::format(fmt::runtime(kCSourceTemplate), fmt::arg("banner", banner), fmt::arg("name", name),
                             fmt::arg("prefix", prefix), fmt::arg("scalar", S), fmt::arg("helpers", helpers),
                             fmt::arg("definitions", definitions));
  return files;
}

}  // namespace proxgen::emit
