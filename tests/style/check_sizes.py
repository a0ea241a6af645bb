#!/usr/bin/env python3
"""Keeps the product code in pieces a reader can hold: no source file over
MAX_FILE_LINES lines and no function over MAX_FUNCTION_LINES lines under
service/, client/ and idl/ (tests, benchmarks and generated code are not product).

    check_sizes.py SOURCE_DIR

Function extents come from universal-ctags (Debian's universal-ctags, installed by
deploy/install-deps.sh): a function runs from the line of its name to the line of
its closing brace, which is how its length is counted here. Prints every file and
function over its limit and exits 1 if there is any; prints the largest of each
otherwise, so a run shows how close the code is.
"""
import json
import os
import shutil
import subprocess
import sys

MAX_FILE_LINES = 700
MAX_FUNCTION_LINES = 80
PRODUCT_DIRS = ("service", "client", "idl")
SUFFIXES = (".cpp", ".hpp", ".h", ".cc")


def product_files(source):
    for top in PRODUCT_DIRS:
        for root, dirs, files in os.walk(os.path.join(source, top)):
            dirs[:] = [d for d in dirs if d not in ("tests", "__pycache__")]
            for name in files:
                if name.endswith(SUFFIXES):
                    yield os.path.join(root, name)


def function_lengths(paths):
    ctags = shutil.which("ctags")
    if ctags is None:
        sys.exit("check_sizes: ctags not found (install universal-ctags: deploy/install-deps.sh)")
    out = subprocess.run(
        [ctags, "--languages=C++", "--language-force=C++", "--kinds-C++=f", "--fields=+ne",
         "--output-format=json", "-f", "-", *paths],
        check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        tag = json.loads(line)
        if "end" in tag:
            yield tag["end"] - tag["line"] + 1, tag["path"], tag["line"], tag["name"]


def main():
    source = os.path.abspath(sys.argv[1])
    paths = sorted(product_files(source))
    if not paths:
        sys.exit(f"check_sizes: no product sources under {source}")
    files = []
    for path in paths:
        with open(path, encoding="utf-8") as f:
            files.append((sum(1 for _ in f), path))
    functions = sorted(function_lengths(paths), reverse=True)
    if not functions:
        sys.exit("check_sizes: ctags reported no functions; cannot measure")

    rel = lambda p: os.path.relpath(p, source)
    problems = [f"{rel(p)}: {n} lines (at most {MAX_FILE_LINES})"
                for n, p in files if n > MAX_FILE_LINES]
    problems += [f"{rel(p)}:{line}: function {name} has {n} lines (at most {MAX_FUNCTION_LINES})"
                 for n, p, line, name in functions if n > MAX_FUNCTION_LINES]
    for problem in problems:
        print(problem)
    largest_file = max(files)
    n, p, line, name = functions[0]
    print(f"{len(files)} files, {len(functions)} functions; largest file {rel(largest_file[1])} "
          f"({largest_file[0]} lines), longest function {name} at {rel(p)}:{line} ({n} lines)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
