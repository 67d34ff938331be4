#!/usr/bin/python3
"""The tests' recorder (tests/support/msm/test/figures.h) writes what the assertion beside it checks.

    report_test_figures_test.py HAMBURGER4_TEST_EXECUTABLE

Runs one test of the executable with MSM_TEST_FIGURES set and checks that the figures it recorded
are the values the test printed for its assertions (to the printed digits), each with its bound,
held; and that without the variable the test writes no figure file.
"""
import json
import os
import re
import subprocess
import sys
import tempfile

TEST = "Hamburger4.EqualsJcgtAlgorithm1UnitDepth"
PRINTED = re.compile(r"\[hamburger4 vs JCGT Alg\. 1, \[0,1\] depth\] distance to the range over 4 ulps: "
                     r"lower p99 \S+ max (\S+), upper p99 \S+ max (\S+); plain difference from the input's bound: "
                     r"p50 \S+ p99 (\S+) max \S+")
# key -> (index of the printed value, the assertion's bound in hamburger4_test.cpp)
EXPECTED = {
    "math.hamburger4_unit_vs_alg1.lower_range_distance_max": (0, 1e-5),
    "math.hamburger4_unit_vs_alg1.upper_range_distance_max": (1, 5e-4),
    "math.hamburger4_unit_vs_alg1.lower_error_p99": (2, 2e-4),
}


def run(executable, environment):
    return subprocess.run([executable, f"--gtest_filter={TEST}"], env=environment, capture_output=True, text=True,
                          timeout=300)


def main(executable):
    executable = os.path.abspath(executable)
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        figures_file = os.path.join(tmp, "figures.jsonl")
        result = run(executable, dict(os.environ, MSM_TEST_FIGURES=figures_file))
        if result.returncode != 0:
            failures.append(f"{TEST} failed:\n{result.stdout[-2000:]}")
        printed = PRINTED.search(result.stdout)
        if not printed:
            failures.append(f"{TEST} printed no line of its figures:\n{result.stdout[-2000:]}")
        figures = {}
        if os.path.exists(figures_file):
            with open(figures_file) as f:
                for line in f:
                    figure = json.loads(line)
                    figures[figure["key"]] = figure
        for key, (index, bound) in EXPECTED.items():
            figure = figures.get(key)
            if figure is None:
                failures.append(f"{key} was not recorded (recorded: {sorted(figures)})")
                continue
            if printed and f"{figure['value']:.2e}" != printed.group(index + 1):
                failures.append(f"{key}: recorded {figure['value']:.2e}, the test printed {printed.group(index + 1)}")
            if (figure["relation"], figure["bound"]) != ("<", bound):
                failures.append(f"{key}: bound {figure['relation']} {figure['bound']}, the assertion's is < {bound}")
            if not (figure["holds"] and figure["value"] < bound):
                failures.append(f"{key}: {figure['value']} does not hold < {bound} (holds: {figure['holds']})")
            if figure["test"] != TEST:
                failures.append(f"{key}: recorded by {figure['test']!r}, not {TEST}")
        if len(figures) != len(EXPECTED):
            failures.append(f"recorded {sorted(figures)}, expected {sorted(EXPECTED)}")

        # Off unless the variable names a file: the same test in a fresh directory writes nothing there.
        environment = {k: v for k, v in os.environ.items() if k != "MSM_TEST_FIGURES"}
        quiet = os.path.join(tmp, "unset")
        os.mkdir(quiet)
        result = subprocess.run([executable, f"--gtest_filter={TEST}"], env=environment, cwd=quiet,
                                capture_output=True, text=True, timeout=300)
        if result.returncode != 0 or os.listdir(quiet):
            failures.append(f"without MSM_TEST_FIGURES: status {result.returncode}, files {os.listdir(quiet)}")
    for f in failures:
        print("FAIL", f)
    print(f"report_test_figures_test: {len(EXPECTED)} figures recorded as asserted" if not failures else
          f"report_test_figures_test: {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
