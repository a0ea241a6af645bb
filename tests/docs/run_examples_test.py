#!/usr/bin/env python3
"""run_examples.py on small made-up docs: it fails for a block that neither
runs nor is marked, for a marker naming no test or of an unknown kind, and for
output that does not match its `# prints:`; it passes what runs and what is
marked.

    run_examples_test.py BUILD_DIR DH3CTL DH3_SERVICE

Prints one line per case; exits 1 if any case went the wrong way, 77 (skip)
when run_examples.py skips (no network namespace).
"""
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD, PROGRAMS = sys.argv[1], sys.argv[2:]

# (what the case shows, README.md's text, the exit status wanted, text the output must hold)
CASES = [
    ("a block that runs passes, its output matched",
     "```sh\nbuild/client/dh3ctl list   # prints: service dh3 on ...\n```\n", 0,
     "every example ran"),
    ("a new block that cannot run and has no marker fails",
     "text\n\n```bash\ncat /etc/dh3/no-such-cell.yaml\n```\n", 1, "FAILED: README.md:5"),
    ("output unlike its '# prints:' fails",
     "```sh\necho moved to 30   # prints: moving to N\n```\n", 1,
     "no line of the output matches 'prints: moving to N'"),
    ("a marker naming no ctest test fails before anything runs",
     "<!-- example: covered by no.such_test -->\n```sh\nsudo apt-get install dh3-tools\n```\n",
     1, "covered by 'no.such_test', which is no ctest test"),
    ("an unknown marker fails",
     "<!-- example: skip -->\n```sh\ntrue\n```\n", 1, "unknown marker 'skip'"),
    ("a block without a language that holds commands fails",
     "```\n$ build/client/dh3ctl list\n```\n", 1, "a block without a language holds commands"),
    ("marked blocks pass without running",
     "<!-- example: not run: needs a cell PC -->\n```sh\ncat /etc/dh3/no-such-cell.yaml\n```\n"
     "<!-- example: covered by docs.examples -->\n```sh\nfalse\n```\n", 0, "every example ran"),
]


def run_case(readme):
    with tempfile.TemporaryDirectory(prefix="dh3-examples-test-") as source:
        os.makedirs(os.path.join(source, "docs"))
        with open(os.path.join(source, "README.md"), "w", encoding="utf-8") as f:
            f.write("# made up\n\n" + readme)
        run = subprocess.run([sys.executable, os.path.join(HERE, "run_examples.py"), source, BUILD,
                              *PROGRAMS], capture_output=True, text=True, check=False)
        return run.returncode, run.stdout + run.stderr


def main():
    wrong = 0
    for what, readme, status, needle in CASES:
        got, output = run_case(readme)
        if got == 77:
            print(f"SKIP: run_examples.py skipped: {output.strip().splitlines()[-1]}")
            return 77
        ok = got == status and needle in output
        print(f"{'ok' if ok else 'WRONG'}: {what} (exit status {got})")
        if not ok:
            wrong += 1
            print("   " + output.rstrip().replace("\n", "\n   "))
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
