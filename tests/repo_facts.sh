#!/usr/bin/env bash
# Facts about the tree that a grep can check: a README a newcomer reads in two minutes, and code and
# docs that speak of what is rather than of how it came to be (no issue numbers, sessions or branch
# names; "branch" as a conditional in code or a tree's branch is fine), and functions short enough to
# read whole or saying why not. Exit 1 naming each breach.
set -uo pipefail
root=${1:-$(dirname "$0")/..}
cd "$root" || exit 2
failed=0
fail() { echo "repo facts: $*" >&2; failed=1; }

words=$(wc -w < README.md)
((words < 1000)) || fail "README.md has $words words (limit 999)"

paths=(src include tools scenes README.md docs/architecture.md docs/techniques.md docs/usage.md docs/viewer.md docs/results.md)
if hits=$(grep -rnIE 'issue #?[0-9]|\bsessions?\b|\bbranch(es)? [a-z0-9]+-[a-z0-9-]+' "${paths[@]}"); then
  fail "history words (issue numbers, sessions, branch names) in code or docs:"
  echo "$hits" >&2
fi
# Technique ids are compared only by the table (its header and rows), the shared headers and the
# shaders' variant selection (and by tests, which check those against each other).
if hits=$(grep -rlI 'MSM_TECH_' src tools bench include | grep -vE \
  '^include/msm/[a-z0-9_]+\.h$|^include/msm/render/frame\.h$|^include/msm/cpu/techniques\.h$|^src/core/techniques\.cpp$|^src/render/shaders/[a-z0-9_]+\.glsl$|_test\.cpp$|^src/core/gpu/kernels\.h$'); then
  fail "technique ids compared outside the technique table, the shared headers and the shaders:"
  echo "$hits" >&2
fi
# A citation of docs/results.md by title ("docs/results.md, \"Title\"", the title possibly wrapped onto the
# next line or cut at the end of one) names the start of one of its headings.
if ! hits=$(python3 - <<'EOF'
import os, re
headings = [l.lstrip("#").strip() for l in open("docs/results.md", encoding="utf-8") if l.startswith("#")]
citation = re.compile(r'results\.md[,:]?[ \t]*(?:\n[ \t]*(?://|#|\*|--)?[ \t]*)?\(?"([^"]{1,200})"')
line_break = re.compile(r'[ \t]*\n[ \t]*(?://+|#|\*|--)?[ \t]*')
for top in ["src", "include", "tools", "scripts", "tests", "bench", "docs", "README.md"]:
    files = [top] if os.path.isfile(top) else [os.path.join(d, f) for d, _, fs in os.walk(top) for f in fs]
    for path in files:
        if path in ("docs/results.md", "tests/repo_facts.sh"):
            continue
        try:
            text = open(path, encoding="utf-8").read()
        except (UnicodeDecodeError, OSError):
            continue
        for m in citation.finditer(text):
            title = line_break.sub(" ", m.group(1)).strip()
            if not any(h.startswith(title) for h in headings):
                print(f"{path}:{text.count(chr(10), 0, m.start()) + 1}: {title}")
EOF
) || [[ -n $hits ]]; then
  fail "citations of docs/results.md whose title is none of its headings:"
  echo "$hits" >&2
fi
# Functions over 120 lines say why above them ("// long: ..."); tests/long_functions.py says how it
# finds a function and what it misses.
if ! python3 tests/long_functions.py --self-test >&2; then
  fail "tests/long_functions.py does not find the functions of its own example"
fi
if ! hits=$(python3 tests/long_functions.py src tools include); then
  fail "functions over 120 lines without a \"long:\" comment above them that says why:"
  echo "$hits" >&2
fi
exit $failed
