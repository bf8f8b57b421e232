#!/usr/bin/env python3
"""Reading and writing the project's YAML and JSON from shell scripts, with parsers (PyYAML and
json), never with sed or awk.

  conf.py get FILE PATH            the value at PATH: a scalar as text (true/false, numbers as
                                   written), a list or mapping as JSON; exit 1 when absent
  conf.py set FILE PATH VALUE      FILE as YAML on stdout with PATH set to VALUE (read as YAML);
                                   missing mapping keys on the way are added (a config lists
                                   only what a deployment sets; the program refuses a key it does
                                   not know, naming it); a list element must exist
  conf.py merge ITEM...            one JSON object on stdout: each ITEM a JSON object (text, or
                                   @FILE for the last line of a file), merged in order; KEY=ITEM
                                   puts ITEM's object under KEY; an empty ITEM is skipped
  conf.py object PAIR...           one JSON object on stdout from KEY=TEXT (a string, as is) and
                                   KEY:=JSON (a number, true, null, a list ...) pairs, in order

FILE may be - (standard input). PATH: keys separated by dots; a list element is chosen by
index (processes.0.config) or by its name field (processes.frontend.config)."""
import json
import sys

import yaml


def load(path):
    text = sys.stdin.read() if path == "-" else open(path).read()
    return yaml.safe_load(text)  # JSON is YAML


def child(node, part):
    if isinstance(node, dict):
        return node, part, part in node
    if isinstance(node, list):
        if part.isdigit():
            i = int(part)
            return node, i, i < len(node)
        for i, item in enumerate(node):
            if isinstance(item, dict) and str(item.get("name")) == part:
                return node, i, True
    return node, part, False


def walk(doc, path, create=False):
    """(container, key) of PATH's last part; SystemExit(1) when a part is absent (with `create`,
    absent mapping keys are added)."""
    node = doc
    parts = path.split(".")
    for n, part in enumerate(parts):
        container, key, present = child(node, part)
        if not present and create and isinstance(container, dict):
            if n < len(parts) - 1:
                container[key] = {}
            present = True
        if not present:
            sys.exit(f"conf.py: no '{'.'.join(parts[:n + 1])}'")
        if n == len(parts) - 1:
            return container, key
        node = container[key]


def text(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, (list, dict)):
        return json.dumps(value)
    return str(value)


def item_object(item):
    if item.startswith("@"):
        with open(item[1:]) as f:
            lines = [l for l in f.read().splitlines() if l.strip()]
        item = lines[-1] if lines else ""
    if not item.strip():
        return None
    value = json.loads(item)
    if not isinstance(value, dict):
        sys.exit(f"conf.py: not a JSON object: {item[:60]}")
    return value


def main(argv):
    if len(argv) >= 3 and argv[0] == "get":
        container, key = walk(load(argv[1]), argv[2])
        print(text(container[key]))
    elif len(argv) == 4 and argv[0] == "set":
        doc = load(argv[1]) or {}
        container, key = walk(doc, argv[2], create=True)
        container[key] = yaml.safe_load(argv[3])
        sys.stdout.write(yaml.safe_dump(doc, sort_keys=False))
    elif argv and argv[0] == "merge":
        out = {}
        for item in argv[1:]:
            key = None
            if "=" in item and not item.lstrip().startswith(("{", "@")):
                key, item = item.split("=", 1)
            value = item_object(item)
            if value is None:
                continue
            if key:
                out[key] = value
            else:
                out.update(value)
        print(json.dumps(out))
    elif argv and argv[0] == "object":
        out = {}
        for pair in argv[1:]:
            key, eq, value = pair.partition("=")
            if not eq or not key:
                sys.exit(f"conf.py object: expected KEY=TEXT or KEY:=JSON, not '{pair}'")
            if key.endswith(":"):
                out[key[:-1]] = json.loads(value)
            else:
                out[key] = value
        print(json.dumps(out))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
