// The expression printer of the emitter: a scalar expression is a constant plus
// a sum of constant * atom terms, where an atom is a run-time value (an input,
// a workspace member, a local temporary) or the product of two such values.
// Constants are known at generation time, so exact zeros and ones fold away
// here (the C++ compiler may not drop `0.0 * x` or `x + 0.0` without
// fast-math). Products of two run-time expressions are materialised into
// temporaries first, so every printed line stays a flat sum of products.
//
// CodeBuilder collects the statements of one function as a tree of blocks and
// prints only the temporaries that some store (transitively) needs, so the
// emitter can compute freely and never leave an unused variable behind.
#pragma once

#include <map>
#include <set>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace proxgen::emit {

enum class ScalarType { Double, Float };

/// Arithmetic of printed statements, counted from the expression graph (how
/// each expression prints: expr.cpp's countOps), for the files' banner.
struct Ops {
  long add = 0;     // binary + and -
  long mul = 0;
  long div = 0;
  long neg = 0;     // unary minus of a run-time value
  long sqrt = 0;
  long sincos = 0;  // proxgen_rt::sincos (one sine and one cosine)
  long log6 = 0;    // proxgen_rt::log6 (the SE(3) logarithm of the runtime)
  static Ops divisions(long n) { Ops o; o.div = n; return o; }
  static Ops multiplications(long n) { Ops o; o.mul = n; return o; }
  Ops& operator+=(const Ops& o);
  friend Ops operator*(long k, const Ops& o);
  friend bool operator==(const Ops& a, const Ops& b);
  long total() const { return add + mul + div + neg + sqrt + sincos + log6; }
};

/// Operations per call as a function of K, the iteration count: once + K * perK
/// (a loop `for (k = a; k < s.iterations ...)` runs K - a times).
struct OpCount {
  Ops once, perK;
  OpCount& operator+=(const OpCount& o) {
    once += o.once;
    perK += o.perK;
    return *this;
  }
  Ops at(long K) const {
    Ops r = once;
    r += K * perK;
    return r;
  }
};

struct Term {
  int atom = 0;
  double coeff = 0;
};

class Expr {
 public:
  Expr() = default;
  Expr(double constant) : c_(constant == 0.0 ? 0.0 : constant) {}  // NOLINT: constants convert
  static Expr atom(int id, double coeff = 1.0);

  double constant() const { return c_; }
  const std::vector<Term>& terms() const { return terms_; }
  bool isConstant() const { return terms_.empty(); }
  bool isZero() const { return terms_.empty() && c_ == 0.0; }
  /// One term and no constant: coeff * atom.
  bool isScaledAtom() const { return terms_.size() == 1 && c_ == 0.0; }
  /// Number of terms plus one for a non-zero constant.
  int size() const { return int(terms_.size()) + (c_ != 0.0 ? 1 : 0); }

  friend Expr operator+(const Expr& a, const Expr& b);
  friend Expr operator-(const Expr& a, const Expr& b);
  friend Expr operator-(const Expr& a);
  friend Expr operator*(double k, const Expr& a);
  Expr& operator+=(const Expr& b) { return *this = *this + b; }
  Expr& operator-=(const Expr& b) { return *this = *this - b; }

 private:
  double c_ = 0.0;
  std::vector<Term> terms_;  // sorted by atom id, no zero coefficients
};

/// Names of inputs and members, numbered once for all the builders of one
/// solver, so a hand-over between builders maps atoms by number, not by text.
class NameTable {
 public:
  int id(const std::string& name);
  const std::string& name(int id) const { return names_[std::size_t(id)]; }

 private:
  std::unordered_map<std::string, int> ids_;
  std::vector<std::string> names_;
};

class CodeBuilder {
 public:
  explicit CodeBuilder(ScalarType scalar, std::shared_ptr<NameTable> names = nullptr);

  ScalarType scalar() const { return scalar_; }
  /// A literal of the solver's Scalar type ("0.5", "0.5f"); throws proxgen::Error
  /// when a constant does not fit the type.
  std::string literal(double v) const;

  // ---- atoms
  /// A value that stays valid in the whole function (an input such as q[3],
  /// a function-scope constant such as mu).
  Expr input(const std::string& text);
  /// The current value of a workspace member (w.IA_x[3]); see store().
  Expr member(const std::string& text);

  // ---- arithmetic that may print temporaries
  Expr mul(const Expr& a, const Expr& b);
  /// e as a plain atom: itself when it is one already, else a temporary.
  Expr temp(const Expr& e, const std::string& hint = "t");
  /// e's current value in a temporary even when e is +-(a member) or a
  /// product of members, so that it can be read after a store overwrites
  /// them; e itself when it is a constant or a multiple of a temporary.
  Expr snapshot(const Expr& e, const std::string& hint = "t");
  /// A temporary when e is more than coeff * atom (before use in many products).
  Expr flat(const Expr& e, const std::string& hint = "t") { return e.size() > 1 || (e.size() == 1 && !e.isScaledAtom()) ? temp(e, hint) : e; }
  Expr recip(const Expr& e, const std::string& hint = "inv");
  Expr sqrt(const Expr& e, const std::string& hint = "r");
  /// fn(arg) for a one-argument <cmath> function, as a temporary.
  Expr call(const std::string& fn, const Expr& arg, const std::string& hint);

  /// A named temporary with a raw right-hand side (printed only when used);
  /// `names`: the parameters the right-hand side reads.
  /// A raw right-hand side computes its `uses` as printed plus `extra` (what the
  /// raw text itself does: a division, a runtime call).
  Expr define(const std::string& name, const std::string& rhs, const std::vector<Expr>& uses,
              const std::vector<std::string>& names = {}, const Ops& extra = {});
  /// True for +-(an input or a member): a value worth no statement of its own.
  bool isAlias(const Expr& e) const;
  /// The same expression in this builder, from another one's members and inputs
  /// (a temporary cannot cross functions: that is an error).
  /// `cache` maps the other builder's atoms to this one's (-1: not yet seen);
  /// pass the same vector for every expression of one hand-over.
  Expr import(const CodeBuilder& from, const Expr& e, std::vector<int>& cache);

  // ---- statements
  /// member = e; returns the member's new value. Earlier values of the member
  /// become stale: printing an expression that still holds one is an error
  /// (it would read the new value where the old one was meant).
  Expr store(const std::string& member, const Expr& e);
  /// The member was written by a statement under another name (a loop's
  /// slot "w.x[r][c0 + j]" writes "w.x[r][c]"): its earlier values become
  /// stale as after store(); returns its new value.
  Expr refresh(const std::string& member);
  /// member = rhs; with a raw right-hand side (a function call).
  Expr storeRaw(const std::string& member, const std::string& rhs, const std::vector<Expr>& uses, const Ops& extra = {});
  /// A raw statement that writes several members (a call with output
  /// arguments); returns their new values, in order.
  std::vector<Expr> storeByCall(const std::string& text, const std::vector<std::string>& members,
                                const std::vector<Expr>& uses, const Ops& extra = {});
  /// A raw statement or comment line with the atoms it reads and the names
  /// (function parameters) its text reads or writes besides them.
  /// `extra`: what the text computes besides printing its uses (a call: the
  /// callee's count); the uses count as printed whole, once each.
  void line(const std::string& text, const std::vector<Expr>& uses = {}, const std::vector<std::string>& names = {},
            const OpCount& extra = {});
  /// Adds `extra` to the statement that defined temporary `e` (a host's mu).
  void addOps(const Expr& e, const Ops& extra);
  void comment(const std::string& text);
  void blank();
  /// Opens a nested block: `head` is printed before the braces' contents
  /// ("{" or "for (...) {"), with comment lines above it.
  void open(const std::string& head, const std::vector<std::string>& comments = {}, const std::vector<std::string>& names = {});
  void close();
  int depth() const { return int(stack_.size()) - 1; }
  int statementCount() const { return int(stmts_.size()); }

  std::string print(const Expr& e) const;
  /// print() without the staleness checks (for comparing states).
  std::string describe(const Expr& e) const;
  /// The function body, indented by `indent` spaces, without the unused temporaries.
  std::string render(int indent) const;
  /// Every input, member and parameter the printed statements read or write
  /// (the texts: "q[3]", "w.v_x[2]", "mu", "s", ...): what a function's parameter list needs.
  std::set<std::string> accessedNames() const;

  /// Number of multiplications in the live statements (for the docs' statistics).
  struct Stats {
    int statements = 0, temporaries = 0, multiplies = 0;
  };
  Stats stats() const;
  /// The arithmetic of the live statements; a loop on s.iterations counts
  /// in OpCount::perK (its head is read for its trip count: open()).
  OpCount opCount() const;
  /// The arithmetic of e as print() prints it.
  Ops countOps(const Expr& e) const;

 private:
  struct Atom {
    std::string text;
    int f1 = -1, f2 = -1;   // factors of a product atom
    int block = 0;          // block that declared it (0: function scope)
    int name = -1;          // NameTable id of an input or member
    int stmt = -1;          // statement defining a temporary
    bool stale = false;     // a member overwritten since
    bool dead = false;      // a temporary whose block has closed
    bool temp = false;
  };
  struct Stmt {
    std::string text;
    int defines = -1;       // temporary atom defined here
    std::vector<int> uses;  // simple atoms read
    int multiplies = 0;
    bool always = false;    // stores, comments, raw lines
    std::vector<std::string> names;  // members written, parameters a raw text reads or writes
    OpCount ops;
  };
  struct Node {
    bool isBlock = false;
    int index = 0;
  };
  struct Block {
    std::string head;
    std::vector<std::string> names;  // parameters the head reads
    std::vector<std::string> comments;
    std::vector<Node> nodes;
    std::map<std::string, int> memo;  // canonical expression -> temporary atom
    long trips = 1;     // a loop: runs trips (+ K when onK) times
    bool onK = false;
  };

  int newAtom(Atom a);
  Expr newTemp(const Expr& e, const std::string& hint);  // temp() and snapshot() after their checks
  int& current(int name);
  std::string key(const Expr& e) const;
  void collectUses(const Expr& e, std::vector<int>& uses) const;
  void check(const Expr& e) const;
  int addStmt(Stmt s);
  std::string freshName(const std::string& hint);
  int countMultiplies(const Expr& e) const;
  void markLive(int block, std::vector<char>& live) const;
  bool blockLive(int block, const std::vector<char>& live) const;
  void countBlock(int block, const std::vector<char>& live, OpCount& out) const;
  void renderBlock(int block, int indent, const std::vector<char>& live, std::string& out) const;

  ScalarType scalar_;
  std::vector<Atom> atoms_;
  std::shared_ptr<NameTable> names_;
  std::vector<int> byName_;  // NameTable id -> current atom of that input/member (-1: none yet)
  std::map<std::pair<int, int>, int> products_;
  std::vector<Stmt> stmts_;
  std::vector<Block> blocks_;
  std::vector<int> stack_;
  std::map<std::string, int> nameCount_;
};

}  // namespace proxgen::emit
