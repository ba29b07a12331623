#include "emit/function.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace proxgen::emit {
namespace {

bool startsWith(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

// Whether a function with these accessed names (CodeBuilder::accessedNames)
// needs parameter `p`: an array (q, v, tau: "q[3]"), the workspace ("w.x"),
// or a scalar ("mu").
bool needs(const std::set<std::string>& names, const std::string& p) {
  if (names.count(p)) return true;  // the name itself (a call's argument)
  if (p == "w") {
    const auto it = names.lower_bound("w.");
    return it != names.end() && startsWith(*it, "w.");
  }
  const auto it = names.lower_bound(p + "[");
  return it != names.end() && startsWith(*it, p + "[");
}

}  // namespace

void FunctionWriter::translate(const CodeBuilder& from, CodeBuilder& to) {
  std::vector<int> cache;
  forEachExpr(live_, [&](Expr& e) {
    if (!e.isConstant()) e = to.import(from, e, cache);
  });
}

void FunctionWriter::beginHost(const std::string& name, const CodeBuilder* from) {
  if (part_) throw std::logic_error("emitter: a host opened inside a part");
  Host h{name, std::make_unique<CodeBuilder>(scalar_, names_), Expr(), Expr(), "", ""};
  if (from) translate(*from, *h.cb);
  cb_ = h.cb.get();
  hosts_.push_back(std::move(h));
}

void FunctionWriter::setHostMu(const Expr& mu) {
  hosts_.back().mu = mu;
  hosts_.back().cb->addOps(mu, Ops::multiplications(1));
}

void FunctionWriter::setHostInvMu(const Expr& inv) {
  hosts_.back().invMu = inv;
  hosts_.back().cb->addOps(inv, Ops::divisions(1));
}

OpCount FunctionWriter::hostOps(const std::string& name) const {
  const auto it = hostOps_.find(name);
  return it == hostOps_.end() ? OpCount{} : it->second;
}

void FunctionWriter::beginPass(const std::string& name, const std::string& banner) {
  endPart();
  hosts_.back().pass = name;
  hosts_.back().banner = banner;
}

void FunctionWriter::boundary(int body) {
  const bool twin = part_ && !joined_ && lastBody_ >= 0 && bodyShapes_[std::size_t(body)] == bodyShapes_[std::size_t(lastBody_)];
  joined_ = twin;
  lastBody_ = body;
  if (twin) {
    lastLabel_ = bodyNames_[std::size_t(body)];
    return;
  }
  open(bodyNames_[std::size_t(body)]);
}
void FunctionWriter::boundary(const std::string& label) {
  lastBody_ = -1;
  open(label);
}

void FunctionWriter::open(const std::string& label) {
  if (part_ && part_->statementCount() >= kPartBudget) endPart();
  if (!part_) {
    part_ = std::make_unique<CodeBuilder>(scalar_, names_);
    translate(*cb_, *part_);
    cb_ = part_.get();
    firstLabel_ = label;
  }
  lastLabel_ = label;
}

// <host>[_<pass>][_<first block>[_to_<last block>]], made unique with _2, _3, ...
std::string FunctionWriter::partName(const Host& host) {
  std::string name = host.name;
  if (!host.pass.empty()) name += "_" + host.pass;
  if (!firstLabel_.empty()) name += "_" + firstLabel_;
  if (!lastLabel_.empty() && lastLabel_ != firstLabel_) name += "_to_" + lastLabel_;
  std::string unique = name;
  for (int k = 2; partNames_.count(unique); ++k) unique = fmt::format("{}_{}", name, k);
  partNames_.insert(unique);
  return unique;
}

std::string FunctionWriter::render(CodeBuilder& cb) {
  const CodeBuilder::Stats st = cb.stats();
  stats_.statements += st.statements;
  stats_.temporaries += st.temporaries;
  stats_.multiplies += st.multiplies;
  return cb.render(2);
}

void FunctionWriter::endPart() {
  if (!part_) return;
  Host& host = hosts_.back();
  const std::string body = render(*part_);
  const std::set<std::string> accessed = part_->accessedNames();
  const OpCount ops = part_->opCount();
  std::vector<std::string> params, args;
  std::vector<Expr> uses;
  for (const char* p : {"q", "v", "tau", "qdd", "lambda"})  // qdd, lambda: inverse_dynamics's inputs
    if (needs(accessed, p)) {
      params.push_back(fmt::format("const Scalar* PROXGEN_RT_RESTRICT {}", p));
      args.push_back(p);
    }
  for (const char* p : {"mu", "inv_mu"})
    if (needs(accessed, p)) {
      params.push_back(fmt::format("Scalar {}", p));
      args.push_back(p);
      uses.push_back(std::string(p) == "mu" ? host.mu : host.invMu);
    }
  if (needs(accessed, "w")) {
    params.push_back("Workspace& PROXGEN_RT_RESTRICT w");
    args.push_back("w");
  }
  for (const char* p : {"M", "Minv"})  // an output written where it is computed (mass_matrix, mass_matrix_inverse)
    if (needs(accessed, p)) {
      params.push_back(fmt::format("Scalar* PROXGEN_RT_RESTRICT {}", p));
      args.push_back(p);
    }
  std::string sig, call;
  for (std::size_t k = 0; k < params.size(); ++k) {
    sig += (k ? ", " : "") + params[k];
    call += (k ? ", " : "") + args[k];
  }
  translate(*part_, *host.cb);
  cb_ = host.cb.get();
  part_.reset();  // its values now live in the host: the part's atoms are not needed again
  if (body.find_first_not_of(" \n") == std::string::npos) return;  // everything folded to constants: no function
  const std::string name = partName(host);
  partsText_ += fmt::format("PROXGEN_RT_NOINLINE void {}({}) noexcept {{\n{}}}\n\n", name, sig, body);
  partHost_[name] = host.name;
  if (!host.banner.empty()) {
    cb_->comment("---- " + host.banner);
    host.banner.clear();
  }
  cb_->line(fmt::format("{}({});", name, call), uses, args, ops);
}

std::string FunctionWriter::endHost(const std::vector<std::string>& params) {
  endPart();
  Host& host = hosts_.back();
  std::string body = render(*host.cb);
  // A parameter the body never reads (no constraints, no joints) is marked used.
  const std::set<std::string> accessed = host.cb->accessedNames();
  std::string prefix;
  for (const std::string& p : params)
    if (!needs(accessed, p)) prefix += "  static_cast<void>(" + p + ");\n";
  hostOps_[host.name] = host.cb->opCount();
  lastHost_ = host.cb.get();
  closed_.push_back(std::move(host.cb));
  hosts_.pop_back();
  cb_ = hosts_.empty() ? closed_.back().get() : hosts_.back().cb.get();
  return prefix + body;
}

}  // namespace proxgen::emit
