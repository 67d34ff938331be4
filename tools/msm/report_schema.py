#!/usr/bin/python3
"""Validates a JSON document against a JSON Schema (the 2020-12 keywords docs/results.schema.json uses).

Debian 12's Python has no JSON Schema package among msm's dependencies; this covers the keywords
the results schema uses and refuses a schema that uses any other, so that no constraint is ignored
silently.

    report_schema.py SCHEMA DOCUMENT...   exit status 0 when every document is valid, else 1
"""
import json
import re
import sys

ANNOTATIONS = {"$schema", "$id", "title", "description", "$defs"}
TYPES = {
    "object": lambda v: isinstance(v, dict),
    "array": lambda v: isinstance(v, list),
    "string": lambda v: isinstance(v, str),
    "boolean": lambda v: isinstance(v, bool),
    "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
    "number": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
    "null": lambda v: v is None,
}


class SchemaError(Exception):
    pass


def _resolve(root, ref):
    if not ref.startswith("#/"):
        raise SchemaError(f"$ref {ref}: only references inside the schema are supported")
    node = root
    for part in ref[2:].split("/"):
        node = node[part]
    return node


def errors(schema, value, root=None, path="$"):
    """The list of messages, each naming the path of the value that breaks a constraint."""
    root = schema if root is None else root
    out = []
    for key, want in schema.items():
        if key in ANNOTATIONS or key in ("properties", "additionalProperties"):
            continue
        if key == "$ref":
            out += errors(_resolve(root, want), value, root, path)
        elif key == "type":
            kinds = want if isinstance(want, list) else [want]
            if not any(TYPES[k](value) for k in kinds):
                out.append(f"{path}: expected {' or '.join(kinds)}, found {type(value).__name__}")
        elif key == "const":
            if value != want:
                out.append(f"{path}: expected {want!r}, found {value!r}")
        elif key == "enum":
            if value not in want:
                out.append(f"{path}: {value!r} is not one of {want}")
        elif key == "required":
            if isinstance(value, dict):
                out += [f"{path}: missing key {k!r}" for k in want if k not in value]
        elif key in ("minimum", "maximum", "exclusiveMinimum"):
            if TYPES["number"](value):
                bad = {"minimum": value < want, "maximum": value > want, "exclusiveMinimum": value <= want}[key]
                if bad:
                    out.append(f"{path}: {value} breaks {key} {want}")
        elif key == "minLength":
            if isinstance(value, str) and len(value) < want:
                out.append(f"{path}: shorter than {want}")
        elif key == "pattern":
            if isinstance(value, str) and not re.search(want, value):
                out.append(f"{path}: {value!r} does not match {want}")
        elif key == "minItems":
            if isinstance(value, list) and len(value) < want:
                out.append(f"{path}: fewer than {want} items")
        elif key == "minProperties":
            if isinstance(value, dict) and len(value) < want:
                out.append(f"{path}: fewer than {want} keys")
        elif key == "items":
            if isinstance(value, list):
                for i, item in enumerate(value):
                    out += errors(want, item, root, f"{path}[{i}]")
        else:
            raise SchemaError(f"keyword {key!r} at {path} is not supported by this validator")
    if isinstance(value, dict):
        properties = schema.get("properties", {})
        extra = schema.get("additionalProperties", True)
        for k, v in value.items():
            if k in properties:
                out += errors(properties[k], v, root, f"{path}.{k}")
            elif extra is False:
                out.append(f"{path}: unexpected key {k!r}")
            elif isinstance(extra, dict):
                out += errors(extra, v, root, f"{path}.{k}")
    return out


def validate_file(schema_path, document_path):
    with open(schema_path) as f:
        schema = json.load(f)
    with open(document_path) as f:
        document = json.load(f)
    return errors(schema, document, schema)


def main(argv):
    if len(argv) < 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    status = 0
    for path in argv[2:]:
        problems = validate_file(argv[1], path)
        for p in problems[:20]:
            print(f"{path}: {p}", file=sys.stderr)
        if problems:
            status = 1
        else:
            print(f"{path}: valid against {argv[1]}")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv))
