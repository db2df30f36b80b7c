#!/usr/bin/env python3
"""Size limits of the host library (host/src): no function over 80 lines and
no class over 300, counted in physical lines.

A function's lines are lizard's (from its signature to its closing brace). A
class's lines are its definition in the header plus every member function
defined outside it (`Class::member`, lizard's names), so moving a class's
code out of its header does not hide it. Exempt: code a tool generates and
tables (EXEMPT below, each with its reason).

  code_size.py [--root DIR] [--python PYTHON]   check; exit 1 naming each excess
  code_size.py --self-test                      the checks on a made-up source
lizard comes from the venv scripts/deps.sh makes (build/host-tools).
"""
import argparse
import os
import re
import sys
import tempfile

FUNCTION_LIMIT = 80
CLASS_LIMIT = 300
# "name as lizard gives it or class name": why it may be longer.
EXEMPT = {}

CLASS_HEAD = re.compile(r"^(?P<indent>\s*)(?:template\s*<[^;{]*>\s*)?(?:class|struct)\s+(?:\[\[[^\]]*\]\]\s*)?(?P<name>[\w:]*\w)"
                        r"(?:\s+final)?\s*(?::[^;{]*)?\{", re.M)


def class_spans(text):
    """(name, first line, last line) of each class or struct defined in `text`, nested ones too."""
    spans = []
    for m in CLASS_HEAD.finditer(text):
        depth, i = 0, m.end() - 1
        while i < len(text):
            c = text[i]
            if c == "{":
                depth += 1
            elif c == "}":
                depth -= 1
                if depth == 0:
                    break
            i += 1
        first = text.count("\n", 0, m.start()) + 1
        last = text.count("\n", 0, i) + 1
        spans.append((m.group("name").split("::")[-1], first, last))
    return spans


def measure(root):
    import lizard  # from the venv

    functions, classes, texts = [], {}, {}
    for folder, _, files in os.walk(root):
        for name in sorted(files):
            if name.endswith((".cpp", ".hpp")):
                path = os.path.join(folder, name)
                with open(path, encoding="utf-8") as f:
                    texts[os.path.relpath(path, root)] = f.read()
    for rel, text in sorted(texts.items()):
        for cls, first, last in class_spans(text):
            classes.setdefault(cls, []).append((f"{rel}:{first}", last - first + 1))
    for rel, text in sorted(texts.items()):
        spans = class_spans(text)
        for fn in lizard.analyze_file.analyze_source_code(rel, text).function_list:
            lines = fn.end_line - fn.start_line + 1
            functions.append((fn.name, f"{rel}:{fn.start_line}", lines))
            # An out-of-line member counts towards its class (the innermost one
            # named); a qualifier that names no class here is a namespace.
            qualified = fn.name.split("::")
            if len(qualified) > 1 and qualified[-2] in classes and not _inside_class(fn.start_line, spans):
                classes[qualified[-2]].append((f"{rel}:{fn.start_line} {fn.name}", lines))
    return functions, classes


def _inside_class(line, spans):
    return any(first <= line <= last for _, first, last in spans)


def findings(root):
    functions, classes = measure(root)
    out = []
    for name, where, lines in functions:
        if lines > FUNCTION_LIMIT and name not in EXEMPT:
            out.append(f"function {name} ({where}) has {lines} lines, over {FUNCTION_LIMIT}")
    for name, parts in sorted(classes.items()):
        total = sum(lines for _, lines in parts)
        if total > CLASS_LIMIT and name not in EXEMPT:
            out.append(f"class {name} has {total} lines, over {CLASS_LIMIT}: " +
                       ", ".join(f"{where} ({lines})" for where, lines in parts))
    return out, functions, classes


def self_test():
    long_body = "\n".join(f"  x += {i};" for i in range(FUNCTION_LIMIT))
    members = "\n".join(f"int Big::f{i}() {{\n{long_body[:400]}\n  return 0;\n}}" for i in range(40))
    source = (f"int longFunction() {{\n  int x = 0;\n{long_body}\n  return x;\n}}\n"
              f"int shortFunction() {{ return 1; }}\n"
              f"class Big {{\n public:\n  int g();\n}};\n{members}\n")
    root = tempfile.mkdtemp(prefix="code-size-")
    with open(os.path.join(root, "a.cpp"), "w", encoding="utf-8") as f:
        f.write(source)
    got, _, _ = findings(root)
    checks = {"a long function": any("longFunction" in g for g in got),
              "a short function passes": not any("shortFunction" in g for g in got),
              "a class with out-of-line members": any(g.startswith("class Big") for g in got)}
    for what, ok in checks.items():
        print(f"self-test {what}: {'ok' if ok else 'WRONG'}")
    return sum(not ok for ok in checks.values())


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=os.path.normpath(os.path.join(here, "..", "..", "src")))
    parser.add_argument("--self-test", action="store_true")
    parser.add_argument("--report", action="store_true", help="also list the longest functions and classes")
    args = parser.parse_args()
    if args.self_test:
        return 1 if self_test() else 0
    problems, functions, classes = findings(args.root)
    if args.report:
        for name, where, lines in sorted(functions, key=lambda f: -f[2])[:10]:
            print(f"  {lines:4d}  {name}  {where}")
        for name, parts in sorted(classes.items(), key=lambda c: -sum(p[1] for p in c[1]))[:10]:
            print(f"  {sum(p[1] for p in parts):4d}  class {name}")
    for p in problems:
        print("code size:", p)
    if problems:
        return 1
    print(f"code size: {len(functions)} functions and {len(classes)} classes in {args.root}: "
          f"none over {FUNCTION_LIMIT} and {CLASS_LIMIT} lines")
    return 0


if __name__ == "__main__":
    sys.exit(main())
