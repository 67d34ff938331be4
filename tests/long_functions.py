#!/usr/bin/env python3
"""Functions over a line limit with no reason written above them.

A function is found by layout, as clang-format leaves it (namespaces not indented): a definition at
namespace level starts at column 0 and its body ends at the next line that is "}" at column 0; a
member function defined in a class at namespace level starts at a two-space indent and ends at the
next "  }". Its length counts from the first line of its signature to that closing brace. A comment
line containing "long:" (or "Long on purpose:") directly above the signature (or above its template line) is the written
reason that lets it be longer.

Limits: a definition inside a macro, a nested class, a function whose body is on its signature line,
or code not formatted by clang-format is not seen; lambdas and local classes count as part of the
function that holds them.

Usage: long_functions.py [--limit N] PATH...  (files or directories; test sources are skipped)
Prints "path:line: name (N lines)" for each breach; exit status 1 if there is one.
       long_functions.py --self-test  (the finder against a made-up source; exit status 1 if it errs)
"""
import os
import re
import sys

EXTENSIONS = (".cpp", ".cc", ".h", ".hpp", ".glsl", ".comp", ".vert", ".frag")
TYPE_START = re.compile(r"^\s*(template\s*<.*>\s*)?(namespace|struct|class|union|enum|extern\s+\"C\")\b")
REASON = re.compile(r"//.*\blong( on purpose)?:", re.IGNORECASE)


def is_test(path):
    name = os.path.basename(path)
    return name.endswith("_test.cpp") or "/test/" in path or "/tests/" in path or path.startswith("tests/")


def source_files(paths):
    for top in paths:
        if os.path.isfile(top):
            yield top
            continue
        for directory, _, names in os.walk(top):
            for name in sorted(names):
                path = os.path.join(directory, name)
                if name.endswith(EXTENSIONS) and not is_test(path):
                    yield path


def has_reason(lines, first):
    """Whether the comment block directly above line `first` (skipping template lines) gives a reason."""
    i = first - 1
    while i >= 0 and lines[i].lstrip().startswith("template"):
        i -= 1
    while i >= 0 and lines[i].lstrip().startswith("//"):
        if REASON.search(lines[i]):
            return True
        i -= 1
    return False


def definitions(lines, indent):
    """(first line, last line, name) of each function body that opens at this indent and closes at it."""
    opening = re.compile(r"^" + " " * indent + r"\S")
    closing = " " * indent + "}"
    start = None  # first line of the declaration being read
    i = 0
    while i < len(lines):
        line = lines[i]
        continuation = start is not None and line.startswith(" " * (indent + 1))
        if not (opening.match(line) or continuation) or line.lstrip().startswith(("//", "#", "}", "public:", "private:", "protected:")):
            if line.strip() == "" or line.lstrip().startswith(("//", "#")):
                start = None
            i += 1
            continue
        if start is None:
            start = i
        if not line.rstrip().endswith("{"):
            if line.rstrip().endswith((";", "}")):
                start = None
            i += 1
            continue
        signature = " ".join(l.strip() for l in lines[start:i + 1])
        if TYPE_START.match(signature) or "(" not in signature or "=" in signature.split("(")[0]:
            start = None
            i += 1
            continue
        end = i + 1
        while end < len(lines) and lines[end].rstrip() != closing:
            end += 1
        name = re.findall(r"([~\w:<>]+)\s*\(", signature.split(")")[0] + ")")
        yield start, end, name[0] if name else signature[:40]
        start = None
        i = end + 1


def class_bodies(lines):
    """Line ranges of classes and structs at namespace level, whose members sit at a two-space indent."""
    i = 0
    while i < len(lines):
        if re.match(r"^(template\s*<.*>\s*)?(struct|class)\b[^;]*\{\s*$", lines[i]):
            end = i + 1
            while end < len(lines) and not lines[end].startswith("}"):
                end += 1
            yield i + 1, end
            i = end
        i += 1


def breaches(path, limit):
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.read().split("\n")
    found = [(s, e, n) for s, e, n in definitions(lines, 0)]
    for first, last in class_bodies(lines):
        body = lines[first:last]
        found += [(first + s, first + e, n) for s, e, n in definitions(body, 2)]
    for start, end, name in found:
        length = end - start + 1
        if length > limit and not has_reason(lines, start):
            yield f"{path}:{start + 1}: {name} ({length} lines)"


def self_test():
    """The finder over a source with long and short functions, with and without a reason."""
    body = ["  x += 1;"] * 125
    source = "\n".join(
        ["namespace a {", "", "// A short one.", "int short_one(int x) {", "  return x;", "}", ""]
        + ["// Without a reason.", "int long_one(int x,", "             int y) {"] + body + ["}", ""]
        + ["// long: a reason.", "template <class T>", "void reasoned(T x) {"] + body + ["}", ""]
        + ["struct S {", "  void member(int x) {"] + body + ["  }", "  int field;", "};", ""]
        + ["void S::outside(int x) {"] + body[:110] + ["}", "", "} // namespace a", ""])
    import tempfile
    with tempfile.NamedTemporaryFile("w", suffix=".cpp", delete=False) as f:
        f.write(source)
    try:
        found = [hit.split(": ", 1)[1] for hit in breaches(f.name, 120)]
    finally:
        os.unlink(f.name)
    expected = ["long_one (128 lines)", "member (127 lines)"]
    if found != expected:
        print(f"long_functions.py --self-test: found {found}, expected {expected}")
        return 1
    return 0


def main(argv):
    if argv == ["--self-test"]:
        return self_test()
    limit = 120
    if len(argv) > 1 and argv[0] == "--limit":
        limit, argv = int(argv[1]), argv[2:]
    hits = [hit for path in source_files(argv) for hit in breaches(path, limit)]
    for hit in hits:
        print(hit)
    return 1 if hits else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
