#!/usr/bin/env python3
"""Checks that docs/protocol-notes.md and what cites it cannot drift apart.

    check_protocol_notes.py SOURCE_DIR

- every quote in the notes, written `line N: "text"`, stands on line N of
  docs/dh3-protocol.md, word for word;
- every repository file the notes name in backticks exists, and every test they
  name (`Suite.Name`) is defined under tests/;
- every citation of a reading in the repository ("protocol-notes.md reading 2",
  "protocol-notes.md readings 1-3, 9") names a reading the notes have;
- nothing in the repository cites a document outside it: no design document
  of the project's founders, no absolute path to one, and the protocol document
  and the notes only by their place in docs/.

Prints one line per problem and exits 1 if there is any.
"""
import os
import re
import sys

SOURCE = sys.argv[1]
NOTES = os.path.join(SOURCE, "docs", "protocol-notes.md")
SPEC = os.path.join(SOURCE, "docs", "dh3-protocol.md")
SKIP_DIRS = {".git", "corpus"}
TEXT_SUFFIXES = (".cpp", ".hpp", ".h", ".py", ".sh", ".md", ".txt", ".cmake", ".in", ".idl",
                 ".yaml", ".xml", ".service", ".conf", "Dockerfile")
# Spelled in pieces so this file does not match itself.
OUTSIDE_DOCUMENTS = [re.compile(r"\bdesign" + r"\.md\b"), re.compile(r"/work" + r"/shared")]

problems = []


def repository_files():
    for root, dirs, files in os.walk(SOURCE):
        dirs[:] = [d for d in dirs if d not in SKIP_DIRS and not d.startswith("build")]
        for name in files:
            if name.endswith(TEXT_SUFFIXES):
                yield os.path.join(root, name)


def read(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


notes = read(NOTES)
spec_lines = read(SPEC).split("\n")

# Readings are "## N. Title".
readings = {int(n) for n in re.findall(r"^## (\d+)\. ", notes, re.M)}
if readings != set(range(1, len(readings) + 1)):
    problems.append(f"protocol-notes.md: readings are not numbered 1..N: {sorted(readings)}")

quotes = re.findall(r'\bline (\d+): "(.+?)"$', notes, re.M)
if not quotes:
    problems.append("protocol-notes.md quotes no line of dh3-protocol.md")
for number, text in quotes:
    n = int(number)
    if n < 1 or n > len(spec_lines):
        problems.append(f"protocol-notes.md: line {n} is beyond dh3-protocol.md's end")
    elif text not in spec_lines[n - 1]:
        problems.append(f'protocol-notes.md: line {n} of dh3-protocol.md does not say "{text}"')

# Files: backticked names with a slash and a dot, not from the vendor's repository.
VENDOR_PATHS = ("include/dh_hand_driver/", "dh_gripper_driver/")
for path in set(re.findall(r"`([\w./-]+/[\w.-]+\.\w+)`", notes)):
    if path.startswith(VENDOR_PATHS):
        continue
    if not os.path.exists(os.path.join(SOURCE, path)):
        problems.append(f"protocol-notes.md names {path}, which does not exist")

defined_tests = set()
for path in repository_files():
    if path.startswith(os.path.join(SOURCE, "tests")) and path.endswith(".cpp"):
        for suite, name in re.findall(r"^TEST(?:_F|_P)?\((\w+),\s*(\w+)\)", read(path), re.M):
            defined_tests.add(f"{suite}.{name}")
named_tests = set(re.findall(r"`([A-Z]\w+\.[A-Z]\w+)`", notes))
if not named_tests:
    problems.append("protocol-notes.md names no test")
for test in sorted(named_tests - defined_tests):
    problems.append(f"protocol-notes.md names the test {test}, which is not defined under tests/")

CITATION = re.compile(r"protocol-notes\.md,?\s+(?:\(?\s*)?readings?\s+([\d][\d\s,\-and]*)")
citations = 0
for path in repository_files():
    relative = os.path.relpath(path, SOURCE)
    if relative == os.path.join("tests", "docs", "check_protocol_notes.py"):
        continue
    text = read(path)
    for pattern in OUTSIDE_DOCUMENTS:
        for match in pattern.finditer(text):
            line = text.count("\n", 0, match.start()) + 1
            problems.append(f"{relative}:{line}: cites {match.group(0)}, which is outside the repository")
    in_docs = relative.startswith("docs" + os.sep)
    for match in re.finditer(r"[\w./-]*(?:dh3-protocol|protocol-notes)\.md", text):
        cited = match.group(0)
        if not (cited.startswith("docs/") or (in_docs and "/" not in cited)):
            line = text.count("\n", 0, match.start()) + 1
            problems.append(f"{relative}:{line}: cites {cited}; in the repository it is "
                            f"docs/{os.path.basename(cited)}")
    for match in CITATION.finditer(text):
        citations += 1
        line = text.count("\n", 0, match.start()) + 1
        for part in re.split(r"\s*(?:,|and)\s*", match.group(1).strip()):
            if not part:
                continue
            bounds = [int(x) for x in part.split("-") if x]
            numbers = range(bounds[0], bounds[-1] + 1)
            for n in numbers:
                if n not in readings:
                    problems.append(f"{relative}:{line}: cites protocol-notes.md reading {n}, "
                                    "which it does not have")
if citations == 0:
    problems.append("nothing in the repository cites a reading of docs/protocol-notes.md")

for problem in problems:
    print(problem)
print(f"{len(quotes)} quotes, {len(named_tests)} tests, {citations} citations checked; "
      f"{len(problems)} problems")
sys.exit(1 if problems else 0)
