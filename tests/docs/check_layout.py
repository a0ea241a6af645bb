#!/usr/bin/env python3
"""Checks that the README's Layout table and docs/architecture.md name every
folder of the tree, so that neither can fall behind the code.

    check_layout.py SOURCE_DIR

The folders: each top-level folder, each service layer (service/*/), each
client folder (client/*/) and each folder under tests/. The README's Layout
section names a folder as `path/`, or as `name/` in the row of the folder that
holds it; docs/architecture.md, which is about the code, names the top-level
folders that build something (a CMakeLists.txt in them), the service layers
and the client folders as `path/...`.

Prints one line per folder missing and exits 1 if there is any.
"""
import os
import re
import sys

SOURCE = sys.argv[1]
SKIP = {".git", "build", "__pycache__"}


def folders(parent=""):
    base = os.path.join(SOURCE, parent)
    return sorted(
        os.path.join(parent, name) if parent else name
        for name in os.listdir(base)
        if os.path.isdir(os.path.join(base, name))
        and name not in SKIP
        and not name.startswith(".")
        and not name.startswith("build")
    )


def layout_section(readme):
    match = re.search(r"^## Layout\n(.*?)(?=^## |\Z)", readme, re.S | re.M)
    return match.group(1) if match else ""


def named_in_layout(section, folder):
    if f"`{folder}/`" in section:
        return True
    parent, name = os.path.split(folder)
    for row in section.splitlines():
        if row.startswith(f"| `{parent}/` |") and f"`{name}/`" in row:
            return True
    return False


def main():
    with open(os.path.join(SOURCE, "README.md"), encoding="utf-8") as f:
        layout = layout_section(f.read())
    with open(os.path.join(SOURCE, "docs", "architecture.md"), encoding="utf-8") as f:
        architecture = f.read()
    top = folders()
    layers = folders("service")
    client = folders("client")
    tests = folders("tests")
    problems = []
    if not layout:
        problems.append("README.md has no '## Layout' section")
    for folder in top + layers + client + tests:
        if not named_in_layout(layout, folder):
            problems.append(f"README.md's Layout does not name {folder}/")
    built = [folder for folder in top if os.path.isfile(os.path.join(SOURCE, folder, "CMakeLists.txt"))]
    for folder in built + layers + client:
        if f"`{folder}/" not in architecture:
            problems.append(f"docs/architecture.md does not name {folder}/")
    for problem in problems:
        print(problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
