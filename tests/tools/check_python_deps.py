#!/usr/bin/python3
"""Every Python module that the repository's tests and scripts import must come from a Debian
package that scripts/install_deps.sh installs by name: a green CI on a machine that has a package
from an earlier hand install must not hide a missing install step (python3-numpy once did).

Python code is found in *.py files and in shell scripts (`python3 - <<'TAG' ... TAG` heredocs and
`python3 -c "..."` one-liners). Modules of the standard library and the repository's own modules
are skipped; every other top-level module is located with the system interpreter and its file is
mapped to its package with `dpkg -S`.

    tests/tools/check_python_deps.py [REPO_ROOT]      exit 0: all packaged; 1: problems listed
"""
import ast
import importlib.util
import os
import re
import subprocess
import sys

SKIP_DIRS = {".git", "build", "logs"}
HEREDOC = re.compile(r"python3\b[^\n]*<<-?\s*'?\"?(\w+)'?\"?[^\n]*\n(.*?)\n\s*\1\s*$", re.S | re.M)
ONE_LINER = re.compile(r"python3\s+-c\s+(\"(?:[^\"\\]|\\.)*\"|'[^']*')")


def python_sources(root):
    """Yields (where, code) for every piece of Python code in the repository."""
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if d not in SKIP_DIRS and not d.startswith("build")]
        for name in files:
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, root)
            if name.endswith(".py"):
                with open(path, encoding="utf-8") as f:
                    yield rel, f.read()
            elif name.endswith(".sh") or name == "run":
                with open(path, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                for m in HEREDOC.finditer(text):
                    yield f"{rel} (heredoc at line {text.count(chr(10), 0, m.start()) + 1})", m.group(2)
                for m in ONE_LINER.finditer(text):
                    code = m.group(1)[1:-1].replace('\\"', '"')
                    yield f"{rel} (python3 -c at line {text.count(chr(10), 0, m.start()) + 1})", code


def imported_modules(where, code):
    try:
        tree = ast.parse(code)
    except SyntaxError as e:
        raise SystemExit(f"check_python_deps: {where}: cannot parse the Python code: {e}")
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name.split(".")[0]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.module.split(".")[0]


def installed_by_script(root):
    """The package names in install_deps.sh's PACKAGES array, as bash sees them."""
    script = os.path.join(root, "scripts", "install_deps.sh")
    out = subprocess.run(
        ["bash", "-c", 'eval "$(sed -n "/^PACKAGES=(/,/^)/p" "$1")"; printf "%s\\n" "${PACKAGES[@]}"', "_", script],
        check=True, capture_output=True, text=True).stdout
    packages = set(out.split())
    if not packages:
        raise SystemExit(f"check_python_deps: no PACKAGES array found in {script}")
    return packages


def module_file(name):
    spec = importlib.util.find_spec(name)
    if spec is None:
        return None
    if spec.origin and spec.origin not in ("built-in", "frozen", "namespace"):
        return spec.origin
    locations = list(spec.submodule_search_locations or [])
    return locations[0] if locations else spec.origin


def owning_package(path):
    r = subprocess.run(["dpkg", "-S", os.path.realpath(path)], capture_output=True, text=True)
    if r.returncode != 0:
        r = subprocess.run(["dpkg", "-S", path], capture_output=True, text=True)
    if r.returncode != 0:
        return None
    return r.stdout.split(":")[0].strip()


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
    local = {os.path.splitext(f)[0] for _, _, files in os.walk(root) for f in files if f.endswith(".py")}
    users = {}
    for where, code in python_sources(root):
        for module in imported_modules(where, code):
            if module in sys.stdlib_module_names or module in local or module == "__future__":
                continue
            users.setdefault(module, []).append(where)

    listed = installed_by_script(root)
    problems = []
    for module in sorted(users):
        where = ", ".join(sorted(set(users[module])))
        path = module_file(module)
        if path is None:
            problems.append(f"module '{module}' (imported by {where}) is not installed: add its Debian package "
                            f"(apt-file search, usually python3-{module}) to scripts/install_deps.sh")
            continue
        package = owning_package(path)
        if package is None:
            problems.append(f"module '{module}' (imported by {where}) comes from {path}, which no Debian package "
                            f"owns (a pip or hand install?): install it from a Debian package in scripts/install_deps.sh")
        elif package not in listed:
            problems.append(f"module '{module}' (imported by {where}) comes from Debian package {package}, which "
                            f"scripts/install_deps.sh does not install: add it to PACKAGES")
        else:
            print(f"ok: {module:16s} {package:24s} ({where})")
    for p in problems:
        print("check_python_deps: " + p, file=sys.stderr)
    print(f"python modules: {len(users) - len(problems)} from install_deps.sh packages, {len(problems)} not")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
