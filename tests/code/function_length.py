#!/usr/bin/env python3
"""No function body over 120 lines outside tests (CONTRIBUTING.md).

    function_length.py SOURCE_DIR   scans SOURCE_DIR's code folders, one line per offender
    function_length.py --self-test  checks the scanner on planted sources

A brace-matching scanner: comments, strings, character literals and preprocessor lines are
blanked first; then at file, namespace, class and extern "C" scope each `{` is classified by
the text before it (since the last `;`, `{` or `}`): a function or lambda body is measured (its
`{` line to its `}` line) and skipped whole, so lambdas and local classes count toward the
function that holds them; namespace, class and extern "C" bodies are scanned inside; anything
else (enum bodies, initialisers, tables) is skipped. Exit status 1 when a function is too long.
"""
import os
import re
import sys
import tempfile

LIMIT = 120
FOLDERS = ("engine", "compute", "render", "app", "bench", "python", "tools", "fuzz")
EXTENSIONS = (".cpp", ".h", ".comp", ".glsl", ".vert", ".frag")
PREFIXES = ("L", "u", "U", "u8")  # of string and character literals

QUALIFIERS = re.compile(
    r"^(\s*(const|constexpr|noexcept(\s*\(\s*\w*\s*\))?|override|final|mutable|volatile|"
    r"&&|&|try|->[^;{}]*))*\s*$")
LAMBDA = re.compile(r"\[[^\[\]]*\]\s*(\([^;{}]*\)\s*)?(mutable|constexpr|noexcept|->[^;{}]*|\s)*$")


def blank(text):
    """The text with comments, literals and preprocessor lines as spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#" or (line_start and c in " \t" and _directive_at(text, i)):
            j = i
            while j < n and text[j] != "\n":
                j = j + 2 if text[j] == "\\" and j + 1 < n else j + 1
            out.append(_spaces(text[i:j]))
            i = j
            continue
        if c == "\n":
            line_start = True
            out.append(c)
            i += 1
            continue
        if c not in " \t":
            line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(_spaces(text[i:j]))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(_spaces(text[i:j]))
            i = j
        elif c == '"' and _raw_prefix(text, i):
            m = re.match(r'"([^ ()\\\t\n]{0,16})\(', text[i:])
            end = text.find(")" + (m.group(1) if m else "") + '"', i)
            j = n if end < 0 or not m else end + len(m.group(1)) + 2
            out.append(_spaces(text[i:j]))
            i = j
        elif c == '"' or (c == "'" and _char_literal(text, i)):
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(_spaces(text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def _directive_at(text, i):
    j = i
    while j < len(text) and text[j] in " \t":
        j += 1
    return j < len(text) and text[j] == "#"


def _spaces(s):
    return re.sub(r"[^\n]", " ", s)


def _identifier_before(text, i):
    j = i
    while j > 0 and (text[j - 1].isalnum() or text[j - 1] == "_"):
        j -= 1
    return text[j:i]


def _raw_prefix(text, i):
    word = _identifier_before(text, i)
    return word.endswith("R") and word[:-1] in ("",) + PREFIXES


def _char_literal(text, i):
    word = _identifier_before(text, i)
    return word == "" or word in PREFIXES  # else a digit separator (1'000)


def _matching(code, i):
    """The index of the `}` closing the `{` at i (len(code) when unclosed)."""
    depth = 0
    for j in range(i, len(code)):
        if code[j] == "{":
            depth += 1
        elif code[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(code)


def _depth0(head):
    """head with the text inside parentheses and angle brackets of templates removed."""
    out, depth = [], 0
    for c in head:
        if c == "(":
            depth += 1
            out.append(c)
        elif c == ")":
            depth = max(0, depth - 1)
            out.append(c)
        elif depth == 0:
            out.append(c)
    return "".join(out)


def classify(head):
    """'function', 'scope' or 'other' for the `{` that follows head."""
    h = re.sub(r"\boperator\s*(\(\s*\)|[^\s(]+)\s*\(", "operator(", head)
    h = re.sub(r"^\s*template\s*<[^{};]*?>\s*", "", h)
    flat = _depth0(h)
    if re.search(r"=\s*$|\breturn\b", flat):
        return "other"
    if "=" in flat:
        return "function" if LAMBDA.search(h) else "other"
    if LAMBDA.search(h) and not re.search(r"\w\s*\(", h.split("[", 1)[0]):
        return "function"
    if re.search(r"\)\s*:[^:]", flat) and re.search(r"[)}]\s*$", flat):
        return "function"  # a constructor with its member initialisers
    close = flat.rfind(")")
    if close >= 0 and "(" in flat[:close] and QUALIFIERS.match(flat[close + 1:]):
        return "function"
    if re.search(r"\b(namespace|class|struct|union)\b", flat) or re.search(r"\bextern\s*$", flat):
        return "scope"
    return "other"


def _in_initialiser_list(head):
    """A constructor's member initialiser (`: a_(x), b_{`): its braces are not the body."""
    flat = _depth0(head)
    return bool(re.search(r"\)\s*:[^:].*[\w>]\s*$", flat, re.S)) or bool(
        re.search(r"\)\s*:\s*[\w:<>]+\s*$", flat))


def long_functions(code, limit=LIMIT):
    """(line, name, lines) of every function body over limit lines in blanked code."""
    found = []
    line_of = _line_index(code)
    head_start = 0
    i = 0
    while i < len(code):
        c = code[i]
        if c in ";}":
            head_start = i + 1
        elif c == "{":
            head = code[head_start:i]
            if _in_initialiser_list(head):  # `b_{y}`: part of the head
                i = _matching(code, i) + 1
                continue
            kind = classify(head)
            if kind == "scope":
                head_start = i + 1
            else:
                end = _matching(code, i)
                lines = line_of(end) - line_of(i) + 1
                if kind == "function" and lines > limit:
                    found.append((line_of(i), _name(head), lines))
                i = end + 1
                head_start = i if kind == "function" else head_start
                continue
        i += 1
    return found


def _line_index(code):
    starts = [0] + [m.end() for m in re.finditer("\n", code)]

    def line_of(pos):
        lo, hi = 0, len(starts) - 1
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if starts[mid] <= pos:
                lo = mid
            else:
                hi = mid - 1
        return lo + 1

    return line_of


def _name(head):
    flat = _depth0(head)
    m = re.search(r"([~\w:]+(?:\s*operator\s*[^\s(]*)?)\s*\(\)[^()]*$", flat)
    if m:
        return m.group(1)
    return "lambda" if "[" in head else "?"


def scan(root):
    offenders = []
    for folder in FOLDERS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, folder)):
            dirnames.sort()
            for name in sorted(filenames):
                if not name.endswith(EXTENSIONS):
                    continue
                path = os.path.join(dirpath, name)
                with open(path, encoding="utf-8", errors="replace") as f:
                    code = blank(f.read())
                for line, fn, lines in long_functions(code):
                    offenders.append((os.path.relpath(path, root), line, fn, lines))
    return offenders


def self_test():
    body = "".join("  x += %d;\n" % k for k in range(LIMIT))  # LIMIT lines + braces: too long
    short = "  x += 1;\n" * 10
    table = "  1,\n" * (LIMIT + 10)
    planted = f"""// A comment with a brace {{ and a string "{{"
#include <string>
#define OPEN {{
namespace outer {{
namespace {{
const char* kText = "}} not a brace";
const char* kRaw = R"raw(
{{ }} }} )" still inside
)raw";
char kBrace = '{{';
int kMillion = 1'000'000;
enum class Colour {{ red, green }};
const int kTable[] = {{
{table}}};
}}  // namespace

struct Holder : Base<int> {{
  Holder(int v) : a_(v), b_{{v}}, c_{{}} {{
{short}  }}
  int get() const override {{ return a_; }}
  Holder& operator=(const Holder& o) {{
{short}    return *this;
  }}
  int a_, b_, c_;
}};

int too_long(int x) {{
{body}  return x;
}}

auto planted_lambda = [](int x) {{
{body}  return x;
}};

void holds_lambda() {{
  auto f = [&](int y) {{
{short}  }};
  struct Local {{ int z; }};
}}

template <typename T>
T fine(T x) noexcept {{
{short}  return x;
}}
extern "C" {{
void c_function(void) {{
{body}}}
}}
}}  // namespace outer
"""
    code = blank(planted)
    assert len(code) == len(planted) and code.count("\n") == planted.count("\n")
    got = [(name, lines) for _, name, lines in long_functions(code)]
    want = [("too_long", LIMIT + 3), ("lambda", LIMIT + 3), ("c_function", LIMIT + 2)]
    if got != want:
        print(f"function_length: self-test failed: found {got}, expected {want}")
        return 1
    glsl = "layout(std430, binding = 0) buffer Data {\n" + "  float v[];\n" * 200 + "} data;\n"
    glsl += "void main() {\n" + short + "}\n"
    if long_functions(blank(glsl)):
        print("function_length: self-test failed: a GLSL buffer block counted as a function")
        return 1
    with tempfile.TemporaryDirectory() as root:
        os.makedirs(os.path.join(root, "engine", "x"))
        with open(os.path.join(root, "engine", "x", "a.cpp"), "w") as f:
            f.write(planted)
        if [o[2] for o in scan(root)] != [w[0] for w in want]:
            print("function_length: self-test failed: scan() missed the planted file")
            return 1
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        status = self_test()
        print("function_length: self-test " + ("ok" if status == 0 else "failed"))
        return status
    if len(argv) != 2:
        print("usage: function_length.py SOURCE_DIR | --self-test", file=sys.stderr)
        return 2
    offenders = scan(argv[1])
    for path, line, name, lines in offenders:
        print(f"{path}:{line}: {name} is {lines} lines, over {LIMIT}: split it into named "
              "functions")
    if not offenders:
        print(f"function_length: no function over {LIMIT} lines in {', '.join(FOLDERS)}")
    return 1 if offenders else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
