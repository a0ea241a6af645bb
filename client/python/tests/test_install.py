"""`cmake --install BUILD --component python` gives a package that imports on
its own: the module, its stubs, and the libdh3client it needs."""

import os
import subprocess
import sys
import tempfile

import pytest

BUILD = os.environ.get("DH3_BUILD_DIR")
INSTALL_DIR = os.environ.get("DH3_PYTHON_INSTALL_DIR")


@pytest.mark.skipif(not BUILD or not INSTALL_DIR, reason="run by ctest, which names the build")
def test_the_installed_package_imports_without_the_build_tree():
    with tempfile.TemporaryDirectory(prefix="dh3-pyinstall-") as prefix:
        subprocess.run(["cmake", "--install", BUILD, "--component", "python", "--prefix", prefix],
                       check=True, capture_output=True)
        package = os.path.join(prefix, INSTALL_DIR, "dh3")
        installed = set(os.listdir(package))
        assert {"__init__.py", "__init__.pyi", "py.typed"} <= installed
        assert any(name.startswith("_dh3.") and name.endswith(".so") for name in installed)
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH")}
        env["PYTHONPATH"] = os.path.join(prefix, INSTALL_DIR)
        code = ("import dh3; print(dh3.__file__); "
                "print(dh3.Client(domain=0).connected()); print(dh3.Code.SERVICE_LOST)")
        run = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                             text=True, timeout=60, cwd=prefix)
        assert run.returncode == 0, run.stderr
        lines = run.stdout.splitlines()
        assert lines[0] == os.path.join(package, "__init__.py")
        assert lines[1:] == ["True", "SERVICE_LOST"]
