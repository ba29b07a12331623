#include "emit/expr.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <regex>
#include <stdexcept>

#include "model/error.hpp"

namespace proxgen::emit {

// ---------------------------------------------------------------- Expr

Expr Expr::atom(int id, double coeff) {
  Expr e;
  if (coeff != 0.0) e.terms_.push_back({id, coeff});
  return e;
}

Expr operator+(const Expr& a, const Expr& b) {
  Expr r;
  r.c_ = a.c_ + b.c_;
  if (r.c_ == 0.0) r.c_ = 0.0;  // no negative zero
  std::size_t i = 0, j = 0;
  while (i < a.terms_.size() || j < b.terms_.size()) {
    if (j == b.terms_.size() || (i < a.terms_.size() && a.terms_[i].atom < b.terms_[j].atom)) {
      r.terms_.push_back(a.terms_[i++]);
    } else if (i == a.terms_.size() || b.terms_[j].atom < a.terms_[i].atom) {
      r.terms_.push_back(b.terms_[j++]);
    } else {
      const double c = a.terms_[i].coeff + b.terms_[j].coeff;
      if (c != 0.0) r.terms_.push_back({a.terms_[i].atom, c});
      ++i;
      ++j;
    }
  }
  return r;
}

Expr operator-(const Expr& a) { return -1.0 * a; }
Expr operator-(const Expr& a, const Expr& b) { return a + (-b); }

Expr operator*(double k, const Expr& a) {
  Expr r;
  if (k == 0.0) return r;
  r.c_ = k * a.c_;
  if (r.c_ == 0.0) r.c_ = 0.0;
  for (const Term& t : a.terms_) {
    const double c = k * t.coeff;
    if (c != 0.0) r.terms_.push_back({t.atom, c});
  }
  return r;
}

// ---------------------------------------------------------------- Ops

Ops& Ops::operator+=(const Ops& o) {
  add += o.add;
  mul += o.mul;
  div += o.div;
  neg += o.neg;
  sqrt += o.sqrt;
  sincos += o.sincos;
  log6 += o.log6;
  return *this;
}

Ops operator*(long k, const Ops& o) {
  Ops r;
  r.add = k * o.add;
  r.mul = k * o.mul;
  r.div = k * o.div;
  r.neg = k * o.neg;
  r.sqrt = k * o.sqrt;
  r.sincos = k * o.sincos;
  r.log6 = k * o.log6;
  return r;
}

bool operator==(const Ops& a, const Ops& b) {
  return a.add == b.add && a.mul == b.mul && a.div == b.div && a.neg == b.neg && a.sqrt == b.sqrt &&
         a.sincos == b.sincos && a.log6 == b.log6;
}

// ---------------------------------------------------------------- CodeBuilder

int NameTable::id(const std::string& name) {
  const auto [it, inserted] = ids_.emplace(name, int(names_.size()));
  if (inserted) names_.push_back(name);
  return it->second;
}

CodeBuilder::CodeBuilder(ScalarType scalar, std::shared_ptr<NameTable> names)
    : scalar_(scalar), names_(names ? std::move(names) : std::make_shared<NameTable>()) {
  blocks_.push_back({});
  stack_.push_back(0);
}

std::string CodeBuilder::literal(double v) const {
  std::string s;
  if (scalar_ == ScalarType::Float) {
    const float f = static_cast<float>(v);
    if (!std::isfinite(f) || (f == 0.0f && v != 0.0 && std::abs(v) >= std::numeric_limits<float>::denorm_min()))
      throw Error(fmt::format("the constant {} cannot be represented as a float", v));
    s = fmt::format("{}", f);
  } else {
    s = fmt::format("{}", v);
  }
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  if (scalar_ == ScalarType::Float) s += "f";
  return s;
}

int CodeBuilder::newAtom(Atom a) {
  atoms_.push_back(std::move(a));
  return int(atoms_.size()) - 1;
}

int& CodeBuilder::current(int name) {
  if (byName_.size() <= std::size_t(name)) byName_.resize(std::size_t(name) + 1, -1);
  return byName_[std::size_t(name)];
}

Expr CodeBuilder::input(const std::string& text) {
  const int name = names_->id(text);
  int& atom = current(name);
  if (atom < 0) {
    Atom a;
    a.text = text;
    a.name = name;
    atom = newAtom(std::move(a));
  }
  return Expr::atom(current(name));
}

Expr CodeBuilder::member(const std::string& text) { return input(text); }

std::string CodeBuilder::key(const Expr& e) const {
  std::string k = fmt::format("{}", e.constant());
  for (const Term& t : e.terms()) k += fmt::format("|{}:{}", t.atom, t.coeff);
  return k;
}

void CodeBuilder::check(const Expr& e) const {
  for (const Term& t : e.terms()) {
    const Atom& a = atoms_[t.atom];
    for (int id : {t.atom, a.f1, a.f2}) {
      if (id < 0) continue;
      if (atoms_[id].stale)
        throw std::logic_error("emitter: stale value of " + atoms_[id].text + " used after it was overwritten");
      if (atoms_[id].dead) throw std::logic_error("emitter: temporary " + atoms_[id].text + " used out of scope");
    }
  }
}

void CodeBuilder::collectUses(const Expr& e, std::vector<int>& uses) const {
  for (const Term& t : e.terms()) {
    const Atom& a = atoms_[t.atom];
    if (a.f1 >= 0) {
      uses.push_back(a.f1);
      uses.push_back(a.f2);
    } else {
      uses.push_back(t.atom);
    }
  }
}

int CodeBuilder::countMultiplies(const Expr& e) const {
  int n = 0;
  for (const Term& t : e.terms()) {
    if (atoms_[t.atom].f1 >= 0) ++n;
    if (t.coeff != 1.0 && t.coeff != -1.0) ++n;
  }
  return n;
}

std::string CodeBuilder::print(const Expr& e) const {
  check(e);
  return describe(e);
}

std::string CodeBuilder::describe(const Expr& e) const {
  // A common factor of two or more terms prints once: c*(x - y), not c*x - c*y.
  if (e.constant() == 0.0 && e.terms().size() > 1) {
    const double c = std::abs(e.terms()[0].coeff);
    bool common = c != 1.0;
    for (const Term& t : e.terms()) common = common && std::abs(t.coeff) == c;
    if (common) {
      Expr unit;
      for (const Term& t : e.terms()) unit += Expr::atom(t.atom, t.coeff / c);
      return literal(c) + "*(" + describe(unit) + ")";
    }
  }
  std::string s;
  if (e.constant() != 0.0 || e.terms().empty()) s = literal(e.constant());
  for (const Term& t : e.terms()) {
    const std::string& x = atoms_[t.atom].text;
    const double a = std::abs(t.coeff);
    const std::string body = a == 1.0 ? x : literal(a) + "*" + x;
    if (s.empty()) s = (t.coeff < 0 ? "-" : "") + body;
    else s += (t.coeff < 0 ? " - " : " + ") + body;
  }
  return s;
}

// The operations of describe(e), term by term as it prints them: a product
// atom is one multiplication, a coefficient other than +-1 another, each term
// after the first an addition or subtraction, a leading term with coefficient
// -1 a negation (-0.5*x multiplies by the literal -0.5, and a negative
// constant is a literal: no operation).
Ops CodeBuilder::countOps(const Expr& e) const {
  Ops o;
  if (e.constant() == 0.0 && e.terms().size() > 1) {
    const double c = std::abs(e.terms()[0].coeff);
    bool common = c != 1.0;
    for (const Term& t : e.terms()) common = common && std::abs(t.coeff) == c;
    if (common) {  // c*(unit)
      Expr unit;
      for (const Term& t : e.terms()) unit += Expr::atom(t.atom, t.coeff / c);
      o = countOps(unit);
      ++o.mul;
      return o;
    }
  }
  bool first = e.constant() == 0.0 && !e.terms().empty();
  for (const Term& t : e.terms()) {
    if (atoms_[std::size_t(t.atom)].f1 >= 0) ++o.mul;
    if (std::abs(t.coeff) != 1.0) ++o.mul;
    if (!first) ++o.add;
    else if (t.coeff == -1.0) ++o.neg;
    first = false;
  }
  return o;
}

int CodeBuilder::addStmt(Stmt s) {
  stmts_.push_back(std::move(s));
  const int id = int(stmts_.size()) - 1;
  blocks_[stack_.back()].nodes.push_back({false, id});
  return id;
}

std::string CodeBuilder::freshName(const std::string& hint) { return fmt::format("{}{}", hint, nameCount_[hint]++); }

Expr CodeBuilder::temp(const Expr& e, const std::string& hint) {
  if (e.isConstant()) return e;
  if (e.isScaledAtom() && e.terms()[0].coeff == 1.0 && atoms_[e.terms()[0].atom].f1 < 0) return e;
  return newTemp(e, hint);
}

Expr CodeBuilder::snapshot(const Expr& e, const std::string& hint) {
  if (e.isConstant()) return e;
  if (e.isScaledAtom() && atoms_[e.terms()[0].atom].temp) return e;  // a temporary is never overwritten
  return newTemp(e, hint);
}

Expr CodeBuilder::newTemp(const Expr& e, const std::string& hint) {
  const std::string k = key(e);
  for (auto b = stack_.rbegin(); b != stack_.rend(); ++b) {
    auto it = blocks_[*b].memo.find(k);
    if (it != blocks_[*b].memo.end()) return Expr::atom(it->second);
  }
  Atom a;
  a.text = freshName(hint);
  a.block = stack_.back();
  a.temp = true;
  const int id = newAtom(a);
  Stmt s;
  s.text = fmt::format("const Scalar {} = {};", atoms_[id].text, print(e));
  s.defines = id;
  collectUses(e, s.uses);
  s.multiplies = countMultiplies(e);
  s.ops.once = countOps(e);
  atoms_[id].stmt = addStmt(std::move(s));
  blocks_[stack_.back()].memo[k] = id;
  return Expr::atom(id);
}

Expr CodeBuilder::mul(const Expr& a, const Expr& b) {
  if (a.isConstant()) return a.constant() * b;
  if (b.isConstant()) return b.constant() * a;
  // Each factor as coeff * simple atom (a product or a sum becomes a temporary).
  auto simple = [&](const Expr& e, double& coeff) {
    if (e.isScaledAtom() && atoms_[e.terms()[0].atom].f1 < 0) {
      coeff = e.terms()[0].coeff;
      return e.terms()[0].atom;
    }
    coeff = 1.0;
    return temp(e).terms()[0].atom;
  };
  double ca = 1, cb = 1;
  int x = simple(a, ca), y = simple(b, cb);
  if (y < x) std::swap(x, y);
  const auto k = std::make_pair(x, y);
  auto it = products_.find(k);
  int id;
  if (it != products_.end()) {
    id = it->second;
  } else {
    Atom p;
    p.text = atoms_[x].text + "*" + atoms_[y].text;
    p.f1 = x;
    p.f2 = y;
    id = newAtom(p);
    products_[k] = id;
  }
  return Expr::atom(id, ca * cb);
}

Expr CodeBuilder::recip(const Expr& e, const std::string& hint) {
  if (e.isConstant()) return 1.0 / e.constant();
  return call("", temp(e), hint);  // an empty function name prints 1 / arg
}

Expr CodeBuilder::call(const std::string& fn, const Expr& arg, const std::string& hint) {
  Atom a;
  a.text = freshName(hint);
  a.block = stack_.back();
  a.temp = true;
  const int id = newAtom(a);
  Stmt s;
  if (fn.empty()) s.text = fmt::format("const Scalar {} = {} / {};", atoms_[id].text, literal(1.0), print(arg));
  else s.text = fmt::format("const Scalar {} = {}({});", atoms_[id].text, fn, print(arg));
  s.defines = id;
  collectUses(arg, s.uses);
  s.multiplies = fn.empty() ? 1 : 0;
  s.ops.once = countOps(arg);
  if (fn.empty()) ++s.ops.once.div;
  else if (fn == "std::sqrt") ++s.ops.once.sqrt;
  else throw std::logic_error("emitter: no operation count for " + fn);
  atoms_[id].stmt = addStmt(std::move(s));
  return Expr::atom(id);
}

Expr CodeBuilder::sqrt(const Expr& e, const std::string& hint) {
  if (e.isConstant()) return std::sqrt(e.constant());
  return call("std::sqrt", temp(e), hint);
}

Expr CodeBuilder::store(const std::string& member, const Expr& e) {
  Stmt s;
  s.text = fmt::format("{} = {};", member, print(e));
  collectUses(e, s.uses);
  s.multiplies = countMultiplies(e);
  s.ops.once = countOps(e);
  s.always = true;
  s.names = {member};
  addStmt(std::move(s));
  return refresh(member);
}

Expr CodeBuilder::storeRaw(const std::string& member, const std::string& rhs, const std::vector<Expr>& uses,
                           const Ops& extra) {
  line(fmt::format("{} = {};", member, rhs), uses, {member}, OpCount{extra, {}});
  return refresh(member);
}

Expr CodeBuilder::define(const std::string& name, const std::string& rhs, const std::vector<Expr>& uses,
                         const std::vector<std::string>& names, const Ops& extra) {
  Atom a;
  a.text = name;
  a.block = stack_.back();
  a.temp = true;
  const int id = newAtom(a);
  Stmt s;
  s.text = fmt::format("const Scalar {} = {};", name, rhs);
  s.defines = id;
  s.names = names;
  s.ops.once = extra;
  for (const Expr& e : uses) {
    check(e);
    collectUses(e, s.uses);
    s.ops.once += countOps(e);
  }
  atoms_[id].stmt = addStmt(std::move(s));
  return Expr::atom(id);
}

bool CodeBuilder::isAlias(const Expr& e) const {
  if (!e.isScaledAtom()) return false;
  const Term& t = e.terms()[0];
  const Atom& a = atoms_[t.atom];
  return (t.coeff == 1.0 || t.coeff == -1.0) && a.f1 < 0 && !a.temp;
}

Expr CodeBuilder::import(const CodeBuilder& from, const Expr& e, std::vector<int>& cache) {
  if (e.isConstant()) return e;
  if (cache.size() < from.atoms_.size()) cache.resize(from.atoms_.size(), -1);
  Expr r(e.constant());
  for (const Term& t : e.terms()) {
    int& id = cache[std::size_t(t.atom)];
    if (id < 0) {
      const Atom& a = from.atoms_[std::size_t(t.atom)];
      Expr x;
      if (a.f1 >= 0) {
        x = mul(import(from, Expr::atom(a.f1), cache), import(from, Expr::atom(a.f2), cache));
      } else if (a.temp || a.stale || a.dead) {
        // Not a value in the other function: poisoned, printing it is an error.
        Atom dead;
        dead.text = a.text;
        dead.dead = true;
        x = Expr::atom(newAtom(dead));
      } else if (a.name >= 0 && from.names_ == names_) {
        int& atom = current(a.name);  // the same name, found by number
        if (atom < 0) {
          Atom b;
          b.text = a.text;
          b.name = a.name;
          atom = newAtom(std::move(b));
        }
        x = Expr::atom(atom);
      } else {
        x = input(a.text);
      }
      id = x.terms()[0].atom;
      if (x.terms()[0].coeff != 1.0) throw std::logic_error("emitter: import of a scaled atom");
    }
    r += Expr::atom(id, t.coeff);
  }
  return r;
}

Expr CodeBuilder::refresh(const std::string& member) {
  const int name = names_->id(member);
  if (current(name) >= 0) atoms_[std::size_t(current(name))].stale = true;
  Atom a;
  a.text = member;
  a.name = name;
  const int id = newAtom(std::move(a));
  current(name) = id;
  return Expr::atom(id);
}

std::vector<Expr> CodeBuilder::storeByCall(const std::string& text, const std::vector<std::string>& members,
                                           const std::vector<Expr>& uses, const Ops& extra) {
  line(text, uses, members, OpCount{extra, {}});
  std::vector<Expr> out;
  for (const std::string& m : members) out.push_back(refresh(m));
  return out;
}

void CodeBuilder::line(const std::string& text, const std::vector<Expr>& uses, const std::vector<std::string>& names,
                       const OpCount& extra) {
  Stmt s;
  s.text = text;
  s.always = true;
  s.names = names;
  s.ops = extra;
  for (const Expr& e : uses) {
    check(e);
    collectUses(e, s.uses);
    s.ops.once += countOps(e);
  }
  addStmt(std::move(s));
}

void CodeBuilder::addOps(const Expr& e, const Ops& extra) {
  if (!e.isScaledAtom() || atoms_[std::size_t(e.terms()[0].atom)].stmt < 0)
    throw std::logic_error("emitter: addOps on a value no statement defines");
  stmts_[std::size_t(atoms_[std::size_t(e.terms()[0].atom)].stmt)].ops.once += extra;
}

void CodeBuilder::comment(const std::string& text) { line("// " + text); }
void CodeBuilder::blank() { line(""); }

void CodeBuilder::open(const std::string& head, const std::vector<std::string>& comments,
                       const std::vector<std::string>& names) {
  Block b;
  b.head = head;
  b.names = names;
  b.comments = comments;
  if (head.rfind("for", 0) == 0 || head.rfind("PROXGEN_RT_NO_UNROLL for", 0) == 0) {
    // The trip count, for opCount(): the passes print loops of one shape,
    // for (int k = A; k < N; ++k) or k <= N, N a literal or s.iterations (K),
    // the column loops after the runtime's pragma that keeps them loops.
    static const std::regex loop(
        R"((?:PROXGEN_RT_NO_UNROLL )?for \(int (\w+) = (-?\d+); \1 (<=?) (\d+|s\.iterations); \+\+\1\) \{)");
    std::smatch m;
    if (!std::regex_match(head, m, loop)) throw std::logic_error("emitter: no trip count for the loop " + head);
    const long from = std::stol(m[2].str()), inclusive = m[3].str() == "<=" ? 1 : 0;
    b.onK = m[4].str() == "s.iterations";
    b.trips = (b.onK ? 0 : std::stol(m[4].str())) - from + inclusive;
  }
  blocks_.push_back(std::move(b));
  const int id = int(blocks_.size()) - 1;
  blocks_[stack_.back()].nodes.push_back({true, id});
  stack_.push_back(id);
}

void CodeBuilder::close() {
  if (stack_.size() <= 1) throw std::logic_error("emitter: close() without open()");
  const int b = stack_.back();
  for (Atom& a : atoms_)
    if (a.temp && a.block == b) a.dead = true;
  stack_.pop_back();
}

// A temporary is live when a live statement reads it. Statements only read
// earlier ones, so one pass in reverse program order settles it.
void CodeBuilder::markLive(int block, std::vector<char>& live) const {
  const Block& b = blocks_[block];
  for (auto n = b.nodes.rbegin(); n != b.nodes.rend(); ++n) {
    if (n->isBlock) {
      markLive(n->index, live);
      continue;
    }
    const Stmt& s = stmts_[n->index];
    if (!s.always && !live[n->index]) continue;
    live[n->index] = 1;
    for (int a : s.uses)
      if (atoms_[a].temp) live[atoms_[a].stmt] = 1;
  }
}

bool CodeBuilder::blockLive(int block, const std::vector<char>& live) const {
  for (const Node& n : blocks_[block].nodes) {
    if (n.isBlock ? blockLive(n.index, live) : (live[n.index] && stmts_[n.index].text.rfind("//", 0) != 0 &&
                                                 !stmts_[n.index].text.empty()))
      return true;
  }
  return false;
}

void CodeBuilder::renderBlock(int block, int indent, const std::vector<char>& live, std::string& out) const {
  const std::string pad(std::size_t(indent), ' ');
  for (const Node& n : blocks_[block].nodes) {
    if (n.isBlock) {
      if (!blockLive(n.index, live)) continue;
      const Block& b = blocks_[n.index];
      for (const std::string& c : b.comments) out += pad + "// " + c + "\n";
      out += pad + b.head + "\n";
      renderBlock(n.index, indent + 2, live, out);
      out += pad + "}\n";
      continue;
    }
    if (!live[n.index]) continue;
    const std::string& t = stmts_[n.index].text;
    out += t.empty() ? "\n" : pad + t + "\n";
  }
}

std::string CodeBuilder::render(int indent) const {
  std::vector<char> live(stmts_.size(), 0);
  markLive(0, live);
  std::string out;
  renderBlock(0, indent, live, out);
  return out;
}

std::set<std::string> CodeBuilder::accessedNames() const {
  std::vector<char> live(stmts_.size(), 0);
  markLive(0, live);
  std::set<std::string> out;
  for (std::size_t k = 0; k < stmts_.size(); ++k) {
    if (!live[k]) continue;
    for (int a : stmts_[k].uses)
      if (atoms_[std::size_t(a)].name >= 0) out.insert(atoms_[std::size_t(a)].text);
    out.insert(stmts_[k].names.begin(), stmts_[k].names.end());
  }
  for (std::size_t b = 1; b < blocks_.size(); ++b)
    if (blockLive(int(b), live)) out.insert(blocks_[b].names.begin(), blocks_[b].names.end());
  return out;
}

void CodeBuilder::countBlock(int block, const std::vector<char>& live, OpCount& out) const {
  for (const Node& n : blocks_[std::size_t(block)].nodes) {
    if (!n.isBlock) {
      if (live[std::size_t(n.index)]) out += stmts_[std::size_t(n.index)].ops;
      continue;
    }
    if (!blockLive(n.index, live)) continue;  // not printed
    const Block& b = blocks_[std::size_t(n.index)];
    OpCount inner;
    countBlock(n.index, live, inner);
    // (trips + K onK) (once + K perK): a K^2 term is a loop on K inside another.
    if (b.onK && inner.perK.total() != 0) throw std::logic_error("emitter: nested loops on s.iterations");
    out.once += b.trips * inner.once;
    out.perK += b.trips * inner.perK;
    if (b.onK) out.perK += inner.once;
  }
}

OpCount CodeBuilder::opCount() const {
  std::vector<char> live(stmts_.size(), 0);
  markLive(0, live);
  OpCount out;
  countBlock(0, live, out);
  return out;
}

CodeBuilder::Stats CodeBuilder::stats() const {
  std::vector<char> live(stmts_.size(), 0);
  markLive(0, live);
  Stats st;
  for (std::size_t k = 0; k < stmts_.size(); ++k) {
    if (!live[k] || stmts_[k].text.empty() || stmts_[k].text.rfind("//", 0) == 0) continue;
    ++st.statements;
    if (stmts_[k].defines >= 0) ++st.temporaries;
    st.multiplies += stmts_[k].multiplies;
  }
  return st;
}

}  // namespace proxgen::emit
