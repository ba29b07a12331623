#include "emit/function.hpp"

#include <fmt/format.h>

#include <cctype>
#include <stdexcept>

namespace proxgen::emit {
namespace {

// Whether code (not its // comments: the generated files have no string
// literals) names the identifier `name`.
bool reads(const std::string& body, const std::string& name) {
  auto ident = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (std::size_t k = 0; k < body.size(); ++k) {
    if (body.compare(k, 2, "//") == 0) {
      k = body.find('\n', k);
      if (k == std::string::npos) return false;
      continue;
    }
    if (body.compare(k, name.size(), name) == 0 && (k == 0 || !ident(body[k - 1])) &&
        (k + name.size() == body.size() || !ident(body[k + name.size()])))
      return true;
  }
  return false;
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
  Host h{name, std::make_unique<CodeBuilder>(scalar_, names_), 0, Expr(), Expr()};
  if (from) translate(*from, *h.cb);
  cb_ = h.cb.get();
  hosts_.push_back(std::move(h));
}

void FunctionWriter::boundary() {
  if (part_ && part_->statementCount() >= kPartBudget) endPart();
  if (part_) return;
  part_ = std::make_unique<CodeBuilder>(scalar_, names_);
  translate(*cb_, *part_);
  cb_ = part_.get();
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
  const bool empty = body.find_first_not_of(" \n") == std::string::npos;
  const std::string name = fmt::format("{}_{}", host.name, empty ? -1 : host.parts++);
  std::vector<std::string> params, args;
  std::vector<Expr> uses;
  for (const char* p : {"q", "v", "tau"})
    if (reads(body, p)) {
      params.push_back(fmt::format("const Scalar* PROXGEN_RT_RESTRICT {}", p));
      args.push_back(p);
    }
  for (const char* p : {"mu", "inv_mu"})
    if (reads(body, p)) {
      params.push_back(fmt::format("Scalar {}", p));
      args.push_back(p);
      uses.push_back(std::string(p) == "mu" ? host.mu : host.invMu);
    }
  if (reads(body, "w")) {
    params.push_back("Workspace& PROXGEN_RT_RESTRICT w");
    args.push_back("w");
  }
  std::string sig, call;
  for (std::size_t k = 0; k < params.size(); ++k) {
    sig += (k ? ", " : "") + params[k];
    call += (k ? ", " : "") + args[k];
  }
  translate(*part_, *host.cb);
  cb_ = host.cb.get();
  part_.reset();  // its values now live in the host: the part's atoms are not needed again
  if (empty) return;  // everything folded to constants: no function
  partsText_ += fmt::format("PROXGEN_RT_NOINLINE void {}({}) noexcept {{\n{}}}\n\n", name, sig, body);
  cb_->line(fmt::format("{}({});", name, call), uses);
}

std::string FunctionWriter::endHost(const std::vector<std::string>& params) {
  endPart();
  Host& host = hosts_.back();
  std::string body = render(*host.cb);
  // A parameter the body never reads (no constraints, no joints) is marked used.
  std::string prefix;
  for (const std::string& p : params)
    if (!reads(body, p)) prefix += "  static_cast<void>(" + p + ");\n";
  lastHost_ = host.cb.get();
  closed_.push_back(std::move(host.cb));
  hosts_.pop_back();
  cb_ = hosts_.empty() ? closed_.back().get() : hosts_.back().cb.get();
  return prefix + body;
}

}  // namespace proxgen::emit
