#include "render/user_source.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "common/error.h"

namespace mcrt {

namespace {

// Three-valued truth of a condition or of a region's activity: and = min, or = max.
enum Tri { kNo = 0, kMaybe = 1, kYes = 2 };
Tri tri_and(Tri a, Tri b) { return std::min(a, b); }
Tri tri_or(Tri a, Tri b) { return std::max(a, b); }
Tri tri_not(Tri a) { return static_cast<Tri>(2 - a); }

enum class Kind { Ident, Number, String, HeaderName, Punct, Other };

struct Token {
    Kind kind;
    std::string text;   // digraphs spelled as their punctuators (C99 6.4.6p3)
    size_t begin, end;  // in the spliced text
    bool bol;           // a new-line (also one inside a comment) since the previous token
    bool nl;            // a new-line outside comments since the previous token: ends a directive
    bool space;         // white space or a comment right before it
};

class Checker {
  public:
    Checker(const std::string& name, const std::string& text) : name_(name), text_(text) {}

    UserSource run(const std::string& required_function);

  private:
    [[noreturn]] void fail(size_t original_offset, const std::string& message) const {
        throw InputError(name_ + ":" + std::to_string(line_of(original_offset)) + ": " + message);
    }
    [[noreturn]] void fail_at(const Token& t, const std::string& message) const {
        fail(orig_[t.begin], message);
    }
    int line_of(size_t offset) const {
        return static_cast<int>(std::upper_bound(line_starts_.begin(), line_starts_.end(), offset) -
                                line_starts_.begin()) +
               1;
    }
    void phases_1_2();
    void lex();
    void directives();
    void directive(size_t first, size_t last);
    Tri evaluate(size_t first, size_t last) const;
    Tri condition(const std::string& d, size_t first, size_t last) const;
    bool value_of(const std::vector<Token>& in, uint64_t& value) const;
    void code(const std::string& required_function, UserSource& out);
    std::string quote(size_t first, size_t last) const;

    const std::string& name_;
    const std::string& text_;
    std::vector<size_t> line_starts_;  // original offsets where lines 2, 3, ... begin
    std::string s_;                    // after line splicing, new-lines as '\n'
    std::vector<size_t> orig_;         // original offset of each character of s_
    std::vector<Token> tokens_;
    std::vector<Token> code_;  // tokens outside directives, in regions that may be active
    std::vector<std::pair<size_t, size_t>> blank_;  // original ranges of `#include "api.cl"`

    struct Macro {
        enum State { Object, Function, Undefined, Unknown } state;
        std::vector<Token> body;
    };
    std::map<std::string, Macro> macros_;
    struct Conditional {
        Tri parent, taken, current;
        bool seen_else;
        size_t token;
    };
    std::vector<Conditional> stack_;
    Tri active() const {
        if (stack_.empty()) return kYes;
        const Conditional& c = stack_.back();
        return tri_and(c.parent, c.current);
    }
};

bool is_ident_start(unsigned char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == '$' || c >= 0x80;
}
bool is_ident_char(unsigned char c) { return is_ident_start(c) || (c >= '0' && c <= '9'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }

// Phase 1 (new-lines: LF, CRLF and CR, as clang counts them) and phase 2 (a backslash, white
// space clang tolerates, then a new-line, is removed). Trigraphs are refused rather than
// replaced: whether the device's compiler replaces them (C99 5.2.1.1) is its choice.
void Checker::phases_1_2() {
    const std::string& t = text_;
    for (size_t i = 0; i < t.size(); ++i) {
        if (t[i] == '\0') fail(i, "contains a NUL byte");
        if (t[i] == '\n' || (t[i] == '\r' && (i + 1 >= t.size() || t[i + 1] != '\n')))
            line_starts_.push_back(i + 1);
    }
    s_.reserve(t.size());
    orig_.reserve(t.size());
    for (size_t i = 0; i < t.size();) {
        if (t[i] == '?' && i + 2 < t.size() && t[i + 1] == '?' && t[i + 2] == '/')
            fail(i, "contains the trigraph ?\?/ (a backslash to some compilers)");
        if (t[i] == '\\') {
            size_t j = i + 1;
            while (j < t.size() && is_space(t[j])) ++j;
            if (j < t.size() && (t[j] == '\n' || t[j] == '\r')) {
                i = j + (t[j] == '\r' && j + 1 < t.size() && t[j + 1] == '\n' ? 2 : 1);
                continue;
            }
        }
        if (t[i] == '\r') {
            s_ += '\n';
            orig_.push_back(i);
            i += i + 1 < t.size() && t[i + 1] == '\n' ? 2 : 1;
            continue;
        }
        s_ += t[i];
        orig_.push_back(i++);
    }
    orig_.push_back(t.size());  // the end, for messages at the end of the file
}

// Phase 3: comments become white space; identifiers, pp-numbers, character and string literals
// (with their L, u, U, u8 prefixes), header names after `# include`, punctuators (C99 6.4).
void Checker::lex() {
    static const char* const kPunctuators[] = {"%:%:", "...", "<<=", ">>=", "->", "++", "--", "<<",
                                               ">>",   "<=",  ">=",  "==",  "!=", "&&", "||", "*=",
                                               "/=",   "%=",  "+=",  "-=",  "&=", "^=", "|=", "##",
                                               "<:",   ":>",  "<%",  "%>",  "%:"};
    static const std::map<std::string, std::string> kDigraphs = {
        {"<:", "["}, {":>", "]"}, {"<%", "{"}, {"%>", "}"}, {"%:", "#"}, {"%:%:", "##"}};
    const std::string& s = s_;
    bool bol = true, nl = true, space = false;
    size_t i = 0;
    while (i < s.size()) {
        char c = s[i];
        if (c == '\n') {
            bol = nl = space = true;
            ++i;
            continue;
        }
        if (is_space(c)) {
            space = true;
            ++i;
            continue;
        }
        if (c == '/' && i + 1 < s.size() && s[i + 1] == '/') {
            while (i < s.size() && s[i] != '\n') ++i;
            space = true;
            continue;
        }
        if (c == '/' && i + 1 < s.size() && s[i + 1] == '*') {
            size_t end = s.find("*/", i + 2);
            // Unterminated, it would swallow mcrt's source after the file.
            if (end == std::string::npos) fail(orig_[i], "unterminated /* comment");
            end += 2;
            if (s.find('\n', i) < end) bol = true;
            i = end;
            space = true;
            continue;
        }
        Token tok{Kind::Other, "", i, i, bol, nl, space};
        // A header name: `<...>` right after `# include` (C99 6.4.7).
        const size_t n = tokens_.size();
        const bool after_include =
            n >= 2 && tokens_[n - 2].text == "#" && tokens_[n - 2].bol &&
            tokens_[n - 1].kind == Kind::Ident &&
            (tokens_[n - 1].text == "include" || tokens_[n - 1].text == "include_next" ||
             tokens_[n - 1].text == "import") &&
            !tok.nl;
        if (c == '<' && after_include) {
            size_t close = i + 1;
            while (close < s.size() && s[close] != '>' && s[close] != '\n') ++close;
            if (close < s.size() && s[close] == '>') {
                tok.kind = Kind::HeaderName;
                i = close + 1;
            }
        }
        if (tok.kind == Kind::HeaderName) {
        } else if (is_ident_start(static_cast<unsigned char>(c))) {
            while (i < s.size() && is_ident_char(static_cast<unsigned char>(s[i]))) ++i;
            tok.kind = Kind::Ident;
            const std::string word = s.substr(tok.begin, i - tok.begin);
            if ((word == "L" || word == "u" || word == "U" || word == "u8") && i < s.size() &&
                (s[i] == '"' || s[i] == '\''))
                c = s[i];  // a prefixed literal: lexed below from the quote on
            else
                c = 0;
        } else if (is_digit(c) || (c == '.' && i + 1 < s.size() && is_digit(s[i + 1]))) {
            ++i;
            while (i < s.size()) {
                char d = s[i];
                if ((d == '+' || d == '-') &&
                    (s[i - 1] == 'e' || s[i - 1] == 'E' || s[i - 1] == 'p' || s[i - 1] == 'P'))
                    ++i;
                else if (is_ident_char(static_cast<unsigned char>(d)) || d == '.')
                    ++i;
                else
                    break;
            }
            tok.kind = Kind::Number;
            c = 0;
        }
        if (tok.kind != Kind::HeaderName && (c == '"' || c == '\'')) {
            // A literal ends at its closing quote or, unterminated, at the end of the line.
            const char quote_char = c;
            if (s[i] == quote_char) {
                ++i;
                while (i < s.size() && s[i] != quote_char && s[i] != '\n')
                    i += s[i] == '\\' ? 2 : 1;
                if (i < s.size() && s[i] == quote_char) ++i;
                i = std::min(i, s.size());
                tok.kind = Kind::String;
            }
        } else if (tok.kind == Kind::Other) {
            size_t length = 1;
            for (const char* p : kPunctuators) {
                size_t l = std::char_traits<char>::length(p);
                if (s.compare(i, l, p) == 0) {
                    length = l;
                    break;
                }
            }
            if (length == 1 && i + 2 < s.size() && c == '?' && s[i + 1] == '?' &&
                std::string("=()'<>!-").find(s[i + 2]) != std::string::npos)
                fail(orig_[i], "contains the trigraph " + s.substr(i, 3) +
                                   " (a punctuator to some compilers)");
            const bool punct =
                std::string("[](){}.&*+-~!/%<>^|?:;=,#").find(c) != std::string::npos;
            tok.kind = punct ? Kind::Punct : Kind::Other;
            i += length;
        }
        tok.end = i;
        tok.text = s.substr(tok.begin, tok.end - tok.begin);
        if (auto d = kDigraphs.find(tok.text); d != kDigraphs.end()) tok.text = d->second;
        tokens_.push_back(tok);
        bol = nl = space = false;
    }
}

// The directive's text for a message: one line, white space collapsed, at most 60 characters.
std::string Checker::quote(size_t first, size_t last) const {
    std::string q;
    for (size_t k = first; k < last; ++k) {
        if (k > first && tokens_[k].space) q += ' ';
        q += tokens_[k].text;
    }
    for (char& c : q)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    if (q.size() > 60) q = q.substr(0, 57) + "...";
    return q;
}

// --- #if expressions (C99 6.10.1): integer arithmetic in intmax_t / uintmax_t ---------------

struct Unknown {};  // the expression cannot be decided here

struct Value {
    bool known;
    bool is_unsigned;
    uint64_t v;
};

class Expression {
  public:
    explicit Expression(std::vector<Value>&& values, std::vector<std::string>&& ops)
        : values_(values), ops_(ops) {}
    // Items: ops_[k] is "" where values_[k] is an operand, else the punctuator.
    Value parse() {
        Value v = conditional();
        if (pos_ != ops_.size()) throw Unknown{};
        return v;
    }

  private:
    bool at(const char* op) const { return pos_ < ops_.size() && ops_[pos_] == op; }
    void enter() {
        if (++depth_ > 200) throw Unknown{};
    }
    Value conditional() {
        enter();
        Value c = binary(0);
        if (at("?")) {
            ++pos_;
            Value a = conditional();
            if (!at(":")) throw Unknown{};
            ++pos_;
            Value b = conditional();
            bool u = a.is_unsigned || b.is_unsigned;
            c = !c.known ? Value{false, u, 0} : c.v ? a : b;
            c.is_unsigned = u;
        }
        --depth_;
        return c;
    }
    static int precedence(const std::string& op) {
        static const std::map<std::string, int> p = {
            {"||", 1}, {"&&", 2}, {"|", 3}, {"^", 4},  {"&", 5},  {"==", 6},
            {"!=", 6}, {"<", 7},  {">", 7}, {"<=", 7}, {">=", 7}, {"<<", 8},
            {">>", 8}, {"+", 9},  {"-", 9}, {"*", 10}, {"/", 10}, {"%", 10}};
        auto it = p.find(op);
        return it == p.end() ? -1 : it->second;
    }
    Value binary(int min_precedence) {
        enter();
        Value left = unary();
        while (pos_ < ops_.size()) {
            const std::string op = ops_[pos_];
            int p = precedence(op);
            if (p < 0 || p < min_precedence) break;
            ++pos_;
            Value right = binary(p + 1);
            left = apply(op, left, right);
        }
        --depth_;
        return left;
    }
    static Value apply(const std::string& op, Value a, Value b) {
        // && and || decide on one known operand (C99 6.5.13, 6.5.14).
        if (op == "&&") {
            if ((a.known && !a.v) || (b.known && !b.v)) return {true, false, 0};
            return {a.known && b.known, false, 1};
        }
        if (op == "||") {
            if ((a.known && a.v) || (b.known && b.v)) return {true, false, 1};
            return {a.known && b.known, false, 0};
        }
        const bool u = a.is_unsigned || b.is_unsigned;
        if (!a.known || !b.known) return {false, u, 0};
        const uint64_t x = a.v, y = b.v;
        const int64_t sx = static_cast<int64_t>(x), sy = static_cast<int64_t>(y);
        auto boolean = [](bool t) { return Value{true, false, t ? 1u : 0u}; };
        if (op == "==") return boolean(x == y);
        if (op == "!=") return boolean(x != y);
        if (op == "<") return boolean(u ? x < y : sx < sy);
        if (op == ">") return boolean(u ? x > y : sx > sy);
        if (op == "<=") return boolean(u ? x <= y : sx <= sy);
        if (op == ">=") return boolean(u ? x >= y : sx >= sy);
        if (op == "|") return {true, u, x | y};
        if (op == "^") return {true, u, x ^ y};
        if (op == "&") return {true, u, x & y};
        if (op == "+") return {true, u, x + y};
        if (op == "-") return {true, u, x - y};
        if (op == "*") return {true, u, x * y};
        if (op == "<<" || op == ">>") {
            if (y >= 64) return {false, a.is_unsigned, 0};
            if (op == "<<") return {true, a.is_unsigned, x << y};
            return {true, a.is_unsigned,
                    a.is_unsigned ? x >> y : static_cast<uint64_t>(sx < 0 ? ~(~sx >> y) : sx >> y)};
        }
        // "/" and "%": by zero, or INTMAX_MIN / -1, is for the compiler to refuse.
        if (y == 0 || (!u && sx == INT64_MIN && sy == -1)) return {false, u, 0};
        if (op == "/") return {true, u, u ? x / y : static_cast<uint64_t>(sx / sy)};
        return {true, u, u ? x % y : static_cast<uint64_t>(sx % sy)};
    }
    Value unary() {
        enter();
        Value v;
        if (at("+") || at("-") || at("~") || at("!")) {
            const std::string op = ops_[pos_++];
            v = unary();
            if (op == "-")
                v.v = 0 - v.v;
            else if (op == "~")
                v.v = ~v.v;
            else if (op == "!")
                v = {v.known, false, v.v ? 0u : 1u};
        } else if (at("(")) {
            ++pos_;
            v = conditional();
            if (!at(")")) throw Unknown{};
            ++pos_;
        } else if (pos_ < ops_.size() && ops_[pos_].empty()) {
            v = values_[pos_++];
        } else {
            throw Unknown{};
        }
        --depth_;
        return v;
    }

    std::vector<Value> values_;
    std::vector<std::string> ops_;
    size_t pos_ = 0;
    int depth_ = 0;
};

// An integer constant (C99 6.4.4.1): decimal, octal or hex, u/l suffixes; anything else unknown.
Value integer_constant(const std::string& t) {
    size_t i = 0;
    uint64_t v = 0;
    int base = 10;
    if (t.size() > 1 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X'))
        base = 16, i = 2;
    else if (t[0] == '0')
        base = 8;
    const size_t digits = i;
    for (; i < t.size(); ++i) {
        int d;
        char c = t[i];
        if (c >= '0' && c <= '9')
            d = c - '0';
        else if (base == 16 && c >= 'a' && c <= 'f')
            d = c - 'a' + 10;
        else if (base == 16 && c >= 'A' && c <= 'F')
            d = c - 'A' + 10;
        else
            break;
        if (d >= base) throw Unknown{};
        if (v > (UINT64_MAX - d) / base) throw Unknown{};
        v = v * base + d;
    }
    if (i == digits) throw Unknown{};
    bool is_unsigned = false;
    for (; i < t.size(); ++i) {
        char c = t[i];
        if (c == 'u' || c == 'U')
            is_unsigned = true;
        else if (c != 'l' && c != 'L')
            throw Unknown{};
    }
    return {true, is_unsigned || v > static_cast<uint64_t>(INT64_MAX), v};
}

// Kinds of directives and the names the check reads in them.
bool conditional_directive(const std::string& d) {
    return d == "if" || d == "ifdef" || d == "ifndef" || d == "elif" || d == "elifdef" ||
           d == "elifndef" || d == "else" || d == "endif";
}
bool reads_files(const std::string& word) {
    return word == "include" || word == "include_next" || word == "import" || word == "embed";
}
bool probes_files(const std::string& word) {
    return word == "__has_include" || word == "__has_include_next" || word == "__has_embed";
}
// Words in a pragma (or a _Pragma string) that read other files or crash clang on purpose
// (`#pragma clang __debug crash`).
bool hostile_pragma_word(const std::string& text) {
    for (const char* w : {"__debug", "dependency", "include_alias"})
        if (text.find(w) != std::string::npos) return true;
    return false;
}

}  // namespace

// The value of the #if expression in tokens [first, last): defined, the file's own macros,
// identifiers it #undef'd as 0 (C99 6.10.1p4); every other name may be a macro of mcrt's kernels,
// the device or the build options, so it is unknown.
Tri Checker::evaluate(size_t first, size_t last) const {
    uint64_t v = 0;
    if (!value_of(std::vector<Token>(tokens_.begin() + first, tokens_.begin() + last), v))
        return kMaybe;
    return v ? kYes : kNo;
}

// The value of the constant expression `in`, if it can be decided here.
bool Checker::value_of(const std::vector<Token>& in, uint64_t& value) const {
    std::vector<Value> values;
    std::vector<std::string> ops;
    size_t budget = 100000;
    auto operand = [&](Value v) {
        values.push_back(v);
        ops.emplace_back();
    };
    auto defined = [&](const std::string& word) {
        auto it = macros_.find(word);
        if (it == macros_.end() || it->second.state == Macro::Unknown)
            return Value{false, false, 0};
        return Value{true, false, it->second.state == Macro::Undefined ? 0u : 1u};
    };
    std::set<std::string> hidden;
    // Lowers tokens to operands and operators, expanding object-like macros (each hidden inside
    // its own expansion, C99 6.10.3.4p2).
    auto lower = [&](auto&& self, const std::vector<Token>& in, int depth) -> void {
        if (depth > 100) throw Unknown{};
        for (size_t k = 0; k < in.size(); ++k) {
            if (budget-- == 0) throw Unknown{};
            const Token& t = in[k];
            if (t.kind == Kind::Ident && t.text == "defined") {
                if (k + 1 < in.size() && in[k + 1].kind == Kind::Ident) {
                    operand(defined(in[++k].text));
                } else if (k + 3 < in.size() && in[k + 1].text == "(" &&
                           in[k + 2].kind == Kind::Ident && in[k + 3].text == ")") {
                    operand(defined(in[k + 2].text));
                    k += 3;
                } else {
                    throw Unknown{};
                }
            } else if (t.kind == Kind::Ident) {
                auto it = macros_.find(t.text);
                if (it == macros_.end() || it->second.state == Macro::Unknown ||
                    it->second.state == Macro::Function || hidden.count(t.text)) {
                    operand({false, false, 0});
                } else if (it->second.state == Macro::Undefined) {
                    operand({true, false, 0});
                } else {
                    hidden.insert(t.text);
                    self(self, it->second.body, depth + 1);
                    hidden.erase(t.text);
                }
            } else if (t.kind == Kind::Number) {
                try {
                    operand(integer_constant(t.text));
                } catch (const Unknown&) {
                    operand({false, false, 0});
                }
            } else if (t.kind == Kind::Punct) {
                values.push_back({false, false, 0});
                ops.push_back(t.text);
            } else {
                operand({false, false, 0});  // a character constant, a string: for the compiler
            }
        }
    };
    try {
        if (in.empty()) return false;
        lower(lower, in, 0);
        Value v = Expression(std::move(values), std::move(ops)).parse();
        value = v.v;
        return v.known;
    } catch (const Unknown&) {
        return false;
    }
}

// One directive, tokens [first, last): tokens_[first] is its `#`.
// The condition of `#if`/`#elif EXPR`, or of `#ifdef`/`#ifndef`/`#elifdef`/`#elifndef NAME`
// (`#ifdef X` is `#if defined X`): what the file's own macros decide, else unknown.
Tri Checker::condition(const std::string& d, size_t first, size_t last) const {
    if (d == "if" || d == "elif") {
        for (size_t k = first + 2; k < last; ++k)
            if (tokens_[k].kind == Kind::Ident && probes_files(tokens_[k].text))
                fail_at(tokens_[k],
                        quote(first, last) + ": an estimator file may not look for other files");
        return evaluate(first + 2, last);
    }
    Tri c = kMaybe;
    if (first + 2 < last && tokens_[first + 2].kind == Kind::Ident) {
        auto it = macros_.find(tokens_[first + 2].text);
        if (it != macros_.end() && it->second.state != Macro::Unknown)
            c = it->second.state == Macro::Undefined ? kNo : kYes;
    }
    return d == "ifndef" || d == "elifndef" ? tri_not(c) : c;
}

void Checker::directive(size_t first, size_t last) {
    const Token& hash = tokens_[first];
    const std::string d = first + 1 < last ? tokens_[first + 1].text : "";
    const bool named = first + 1 < last && tokens_[first + 1].kind == Kind::Ident;
    const Tri reach = active();
    if (named && conditional_directive(d)) {
        if (d == "if" || d == "ifdef" || d == "ifndef") {
            const Tri c = reach != kNo ? condition(d, first, last) : kNo;
            if (stack_.size() >= 4096) fail_at(hash, "conditionals nested more than 4096 deep");
            stack_.push_back({reach, kNo, c, false, first});
            return;
        }
        if (stack_.empty()) fail_at(hash, "#" + d + " without #if");
        Conditional& top = stack_.back();
        if (d == "endif") {
            stack_.pop_back();
            return;
        }
        if (top.seen_else) fail_at(hash, "#" + d + " after #else");
        top.taken = tri_or(top.taken, top.current);
        if (d == "else") {
            top.seen_else = true;
            top.current = tri_not(top.taken);
            return;
        }
        // #elif (and clang's #elifdef, #elifndef): decided only where no earlier branch surely was.
        const Tri c = top.parent != kNo && top.taken != kYes ? condition(d, first, last) : kNo;
        top.current = tri_and(tri_not(top.taken), c);
        return;
    }
    if (reach == kNo) return;       // skipped, as a preprocessor skips it (C99 6.10p4)
    if (first + 1 == last) return;  // the null directive
    if (!named)
        fail_at(hash, quote(first, last) +
                          ": a line marker would make compiler messages "
                          "name other files and lines");
    if (reads_files(d)) {
        if (d == "include" && last == first + 3 && tokens_[first + 2].text == "\"api.cl\"") {
            blank_.push_back({orig_[hash.begin], orig_[tokens_[first + 2].end - 1] + 1});
            return;
        }
        fail_at(hash, quote(first, last) +
                          ": an estimator file may include only \"api.cl\" (the "
                          "kernel API, already in scope; docs/ESTIMATORS.md)");
    }
    if (d == "line")
        fail_at(hash, quote(first, last) +
                          ": #line would make compiler messages name other files and lines");
    if (d == "define" || d == "undef") {
        if (first + 2 >= last || tokens_[first + 2].kind != Kind::Ident)
            return;  // for the compiler
        Macro& m = macros_[tokens_[first + 2].text];
        if (reach == kMaybe) {
            m = Macro{Macro::Unknown, {}};
        } else if (d == "undef") {
            m = Macro{Macro::Undefined, {}};
        } else if (first + 3 < last && tokens_[first + 3].text == "(" &&
                   !tokens_[first + 3].space) {
            m = Macro{Macro::Function, {}};
        } else {
            m = Macro{Macro::Object,
                      std::vector<Token>(tokens_.begin() + first + 3, tokens_.begin() + last)};
        }
        return;
    }
    if (d == "pragma") {
        for (size_t k = first + 2; k < last; ++k)
            if (hostile_pragma_word(tokens_[k].text))
                fail_at(hash, quote(first, last) + ": not a pragma an estimator file may use");
        return;
    }
    if (d == "error" || d == "warning") return;  // the compiler reports it, naming this line
    fail_at(hash, quote(first, last) +
                      ": not a directive an estimator file may use (#define, "
                      "#undef, #if, #ifdef, #ifndef, #elif, #else, #endif, "
                      "#pragma, #error, #warning)");
}

void Checker::directives() {
    for (size_t k = 0; k < tokens_.size();) {
        const Token& t = tokens_[k];
        size_t end = k + 1;
        const bool is_directive = t.text == "#" && t.bol;
        if (is_directive)
            while (end < tokens_.size() && !tokens_[end].nl) ++end;
        const Tri reach = active();
        if (reach != kNo) {
            // Whatever a directive or a macro might make of them: `# include`, `_Pragma("...")`.
            for (size_t j = k; j < end; ++j) {
                const Token& a = tokens_[j];
                if (a.text == "#" && j + 1 < tokens_.size() && tokens_[j + 1].kind == Kind::Ident &&
                    reads_files(tokens_[j + 1].text) && !(is_directive && j == k))
                    fail_at(a, "'# " + tokens_[j + 1].text +
                                   "' outside a directive of its own: an estimator file may "
                                   "include only \"api.cl\"");
                if (a.kind == Kind::Ident && probes_files(a.text))
                    fail_at(a, a.text + ": an estimator file may not look for other files");
                if (a.kind == Kind::Ident && a.text == "_Pragma")
                    for (size_t p = j + 1; p < std::min(tokens_.size(), j + 4); ++p)
                        if (tokens_[p].kind == Kind::String && hostile_pragma_word(tokens_[p].text))
                            fail_at(a, "_Pragma" + tokens_[p].text.substr(0, 40) +
                                           ": not a pragma an estimator file may use");
            }
        }
        if (is_directive)
            directive(k, end);
        else if (reach != kNo)
            code_.push_back(t);
        k = end;
    }
    if (!stack_.empty()) {
        const Token& t = tokens_[stack_.back().token];
        fail_at(t, "#" + tokens_[stack_.back().token + 1].text + " without #endif");
    }
}

namespace {

// Bytes of one element of an OpenCL C type by name (OpenCL C 1.2 sec. 6.1.1-6.1.2; a 3-vector
// takes 4 elements' room); types it does not know count 16.
size_t type_size(const std::string& type) {
    static const std::map<std::string, size_t> scalars = {
        {"char", 1},      {"uchar", 1},    {"bool", 1},   {"short", 2},     {"ushort", 2},
        {"half", 2},      {"int", 4},      {"uint", 4},   {"float", 4},     {"long", 8},
        {"ulong", 8},     {"double", 8},   {"size_t", 8}, {"ptrdiff_t", 8}, {"intptr_t", 8},
        {"uintptr_t", 8}, {"unsigned", 4}, {"signed", 4}};
    if (auto it = scalars.find(type); it != scalars.end()) return it->second;
    size_t digits = type.size();
    while (digits > 0 && is_digit(type[digits - 1])) --digits;
    if (digits < type.size()) {
        auto it = scalars.find(type.substr(0, digits));
        const std::string n = type.substr(digits);
        if (it != scalars.end() && (n == "2" || n == "3" || n == "4" || n == "8" || n == "16"))
            return it->second * (n == "3" ? 4 : std::stoul(n));
    }
    return 16;
}

bool keyword(const std::string& w) {
    static const std::set<std::string> words = {
        "return", "else",   "case",  "default",  "goto",    "sizeof", "do",    "while", "if",
        "for",    "switch", "break", "continue", "typedef", "struct", "union", "enum",  "vec_step"};
    return words.count(w) > 0;
}
bool qualifier(const std::string& w) {
    static const std::set<std::string> words = {"const",    "volatile", "private",  "__private",
                                                "static",   "register", "restrict", "__restrict",
                                                "unsigned", "signed"};
    return words.count(w) > 0;
}

}  // namespace

// File-scope analysis of the tokens that may be compiled: function definitions (`name (...) {`
// at brace depth 0), kernels, the call graph among the file's functions, private arrays.
void Checker::code(const std::string& required_function, UserSource& out) {
    const std::vector<Token>& c = code_;
    struct Function {
        size_t name, body_begin, body_end;  // indices into c; the body is [begin, end)
    };
    std::vector<Function> functions;
    std::map<std::string, std::vector<size_t>> by_name;
    int depth = 0;
    for (size_t k = 0; k < c.size(); ++k) {
        const std::string& t = c[k].text;
        if (t == "{")
            ++depth;
        else if (t == "}")
            depth = std::max(0, depth - 1);
        if (depth != 0 || c[k].kind != Kind::Ident) continue;
        out.file_scope_names.emplace(t, line_of(orig_[c[k].begin]));
        if (t == "kernel" || t == "__kernel") {
            std::string function;
            for (size_t j = k + 1; j + 1 < c.size() && c[j].text != "{" && c[j].text != ";"; ++j)
                if (c[j].kind == Kind::Ident && c[j + 1].text == "(") {
                    function = " '" + c[j].text + "'";
                    break;
                }
            fail_at(c[k], "defines the kernel" + function +
                              ": an estimator file defines functions, which mcrt's kernels call, "
                              "not kernels (docs/ESTIMATORS.md)");
        }
        if (k + 1 >= c.size() || c[k + 1].text != "(") continue;
        size_t j = k + 1;
        int parens = 0;
        for (; j < c.size(); ++j) {
            if (c[j].text == "(")
                ++parens;
            else if (c[j].text == ")" && --parens == 0)
                break;
            else if (c[j].text == "{" || c[j].text == "}" || c[j].text == ";")
                break;
        }
        if (j + 1 >= c.size() || c[j].text != ")" || c[j + 1].text != "{") continue;
        size_t end = j + 1;
        int braces = 0;
        for (; end < c.size(); ++end) {
            if (c[end].text == "{")
                ++braces;
            else if (c[end].text == "}" && --braces == 0)
                break;
        }
        by_name[t].push_back(functions.size());
        functions.push_back({k, j + 2, std::min(end, c.size())});
        if (t == required_function) out.defines_function = true;
        k = end - 1;  // the closing brace is counted by the loop
        depth = end < c.size() ? 1 : 0;
    }

    // The call graph: an identifier followed by `(` in a body, naming one of the file's functions.
    std::map<std::string, std::vector<std::pair<std::string, size_t>>> calls;  // callee, token
    for (const Function& f : functions) {
        auto& edges = calls[c[f.name].text];
        for (size_t k = f.body_begin; k + 1 < f.body_end; ++k)
            if (c[k].kind == Kind::Ident && c[k + 1].text == "(" && by_name.count(c[k].text))
                edges.push_back({c[k].text, k});
    }
    // A cycle, found by depth-first search from each function in the file's order.
    std::map<std::string, int> state;                  // 0 new, 1 on the path, 2 done
    std::vector<std::pair<std::string, size_t>> path;  // function, the call it makes next
    for (const Function& f : functions) {
        const std::string& root = c[f.name].text;
        if (state[root] != 0) continue;
        // Iterative, so that a long chain of calls cannot exhaust the stack.
        std::vector<std::pair<std::string, size_t>> stack = {{root, 0}};
        state[root] = 1;
        while (!stack.empty()) {
            auto& [name, next] = stack.back();
            const auto& edges = calls[name];
            if (next == edges.size()) {
                state[name] = 2;
                stack.pop_back();
                continue;
            }
            const auto& [callee, token] = edges[next++];
            if (state[callee] == 1) {
                // The cycle: from callee's frame on the stack to here.
                size_t from = 0;
                while (stack[from].first != callee) ++from;
                std::string through;
                for (size_t k = from + 1; k < stack.size(); ++k)
                    through += (through.empty() ? "" : ", ") + stack[k].first;
                const size_t call =
                    stack.size() == from + 1 ? token : calls[callee][stack[from].second - 1].second;
                fail_at(c[call], "'" + callee + "' calls itself" +
                                     (through.empty() ? "" : " (through " + through + ")") +
                                     ": OpenCL C forbids recursion (OpenCL C 1.2 sec. 6.9)");
            }
            if (state[callee] == 0) {
                state[callee] = 1;
                stack.push_back({callee, 0});
            }
        }
    }

    // Private arrays of constant size: `T name[N]...` declarations in bodies.
    size_t total = 0;
    size_t largest_token = 0, largest = 0;
    for (const Function& f : functions) {
        bool statement_start = true;
        for (size_t k = f.body_begin; k < f.body_end; ++k) {
            const std::string& t = c[k].text;
            if (t == ";" || t == "{" || t == "}") {
                statement_start = true;
                continue;
            }
            if (!statement_start) continue;
            statement_start = false;
            size_t j = k;
            while (j < f.body_end && c[j].kind == Kind::Ident && qualifier(c[j].text)) ++j;
            if (j + 1 >= f.body_end || c[j].kind != Kind::Ident || keyword(c[j].text)) continue;
            const size_t element = type_size(c[j].text);
            ++j;
            // Declarators: `*`... name ([N])... [= initializer], separated by commas.
            while (j < f.body_end) {
                size_t size = 1;
                bool pointer = false;
                while (j < f.body_end && c[j].text == "*") pointer = true, ++j;
                if (j >= f.body_end || c[j].kind != Kind::Ident || keyword(c[j].text)) break;
                const size_t name = j++;
                bool array = false, known = true;
                while (j < f.body_end && c[j].text == "[") {
                    size_t close = j + 1;
                    int brackets = 1;
                    for (; close < f.body_end; ++close) {
                        if (c[close].text == "[")
                            ++brackets;
                        else if (c[close].text == "]" && --brackets == 0)
                            break;
                    }
                    if (close >= f.body_end) break;
                    // The size as an #if would read it, with the file's own macros.
                    uint64_t n = 0;
                    if (!value_of(std::vector<Token>(c.begin() + j + 1, c.begin() + close), n))
                        known = false;
                    array = true;
                    size = n > 0 && size > (UINT64_MAX >> 1) / n ? (UINT64_MAX >> 1) : size * n;
                    j = close + 1;
                }
                if (array && known) {
                    const size_t bytes = size > (UINT64_MAX >> 1) / 16
                                             ? (UINT64_MAX >> 1)
                                             : size * (pointer ? 8 : element);
                    total = total > (UINT64_MAX >> 1) - bytes ? (UINT64_MAX >> 1) : total + bytes;
                    if (bytes >= largest) largest = bytes, largest_token = name;
                }
                // Skip an initializer, to the next declarator or the end of the statement.
                int nesting = 0;
                while (j < f.body_end) {
                    const std::string& x = c[j].text;
                    if (x == "(" || x == "[" || x == "{")
                        ++nesting;
                    else if (x == ")" || x == "]" || x == "}")
                        --nesting;
                    if (nesting < 0 || (nesting == 0 && (x == "," || x == ";"))) break;
                    ++j;
                }
                if (j < f.body_end && c[j].text == ",") {
                    ++j;
                    continue;
                }
                break;
            }
            k = j - 1;  // continue the scan from where the declaration ended
        }
    }
    out.private_bytes = total;
    if (total > kUserPrivateMemoryLimit)
        fail_at(c[largest_token],
                "private arrays of " + std::to_string(total) + " bytes (the largest '" +
                    c[largest_token].text + "', " + std::to_string(largest) + " bytes): at most " +
                    std::to_string(kUserPrivateMemoryLimit / 1024) +
                    " KiB, as a work-item's private memory lives on a worker thread's stack");
}

UserSource Checker::run(const std::string& required_function) {
    phases_1_2();
    lex();
    directives();
    UserSource out;
    code(required_function, out);
    out.text = text_;
    for (const auto& [begin, end] : blank_)
        for (size_t i = begin; i < end && i < out.text.size(); ++i)
            if (out.text[i] != '\n' && out.text[i] != '\r') out.text[i] = ' ';
    return out;
}

UserSource check_user_source(const std::string& name, const std::string& text,
                             const std::string& required_function) {
    return Checker(name, text).run(required_function);
}

}  // namespace mcrt
