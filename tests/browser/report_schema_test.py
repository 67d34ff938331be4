#!/usr/bin/python3
"""results.json of a run validates against docs/results.schema.json, and the validator refuses
documents that break the schema (so that the first check can fail).

    report_schema_test.py SCHEMA RESULTS.json
"""
import copy
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "msm"))
import report_schema  # noqa: E402


def main(schema_path, results_path):
    with open(schema_path) as f:
        schema = json.load(f)
    with open(results_path) as f:
        results = json.load(f)
    failures = []
    problems = report_schema.errors(schema, results)
    if problems:
        failures.append(f"{results_path} is not valid: {problems[:5]}")

    def broken(description, change, expected_path):
        document = copy.deepcopy(results)
        change(document)
        found = report_schema.errors(schema, document)
        if not any(expected_path in p for p in found):
            failures.append(f"{description}: no error at {expected_path} (found {found[:3]})")

    technique = "$.rows[0].techniques[0]"
    broken("a metric missing", lambda d: d["rows"][0]["techniques"][0]["metrics"].pop("mae"), technique + ".metrics")
    broken("a share above 1", lambda d: d["rows"][0]["techniques"][0]["metrics"].update(share_above_3pct=1.5),
           technique + ".metrics.share_above_3pct")
    broken("a metric of the wrong type", lambda d: d["rows"][0]["techniques"][0]["metrics"].update(mae="0.1"),
           technique + ".metrics.mae")
    broken("an unknown key", lambda d: d["rows"][0].update(colour="red"), "$.rows[0]")
    broken("no device", lambda d: d.pop("device"), "$")
    broken("an unknown effect", lambda d: d["rows"][0]["truth"].update(effect="blurry"), "$.rows[0].truth.effect")
    broken("an image outside the report", lambda d: d["rows"][0]["truth"]["images"].update(render="/etc/x.png"),
           "$.rows[0].truth.images.render")
    broken("no rows", lambda d: d.update(rows=[]), "$.rows")
    if "tests" in results:
        figure = "$.tests.runs[0].figures[0]"
        broken("a test figure without its bound", lambda d: d["tests"]["runs"][0]["figures"][0].pop("bound"), figure)
        broken("a test figure's relation unknown",
               lambda d: d["tests"]["runs"][0]["figures"][0].update(relation="about"), figure + ".relation")
        broken("a test figure's holds not a boolean", lambda d: d["tests"]["runs"][0]["figures"][0].update(holds="yes"),
               figure + ".holds")
    else:
        failures.append(f"{results_path} has no test figures (\"tests\")")
    for f in failures:
        print("FAIL", f)
    print(f"report_schema_test: {results_path}: valid; every broken document refused" if not failures else
          f"report_schema_test: {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))
