#!/usr/bin/env python3
"""Checks docs/ARCHITECTURE.md's crate table against the Cargo manifests (test.sh runs it).

Every crate under crates/ has one row `| `dir` (`name`) | description | uses |`: the
description is the manifest's, and "uses" lists exactly its normal workspace
dependencies (without the alba- prefix; `—` for none; the CLI says `all`).
Also: alba-server uses at most six workspace crates; no `toml` crate under
the compiler (`cargo tree -p alba-compiler -e normal`: the alba.toml reader
is alba-load's, above it, ADR 0014). Then runs check-module-cycles.py (no
module cycle inside any crate).
Exit status 1 with one line per difference.
"""
import glob
import os
import re
import subprocess
import sys
import tomllib

MAX_SERVER_DEPS = 6

ROW = re.compile(r"^\| `([\w-]+)` \(`(alba-[\w-]+)`[^)]*\) \| (.*) \| ([^|]*) \|\s*$")


def main() -> int:
    rows = {}
    for line in open("docs/ARCHITECTURE.md", encoding="utf-8"):
        m = ROW.match(line)
        if m:
            rows[m.group(2)] = (m.group(1), m.group(3).strip(), m.group(4).strip())
    crates = {}
    for path in sorted(glob.glob("crates/*/Cargo.toml")):
        with open(path, "rb") as f:
            manifest = tomllib.load(f)
        crates[manifest["package"]["name"]] = (path, manifest)
    errors = []
    for name, (path, manifest) in crates.items():
        if name not in rows:
            errors.append(f"{path}: {name} has no row in the crate table")
            continue
        folder, description, uses = rows.pop(name)
        if f"crates/{folder}/Cargo.toml" != path:
            errors.append(f"{name}: the table says crates/{folder}, the manifest is {path}")
        want = manifest["package"].get("description", "").strip()
        if description != want:
            errors.append(f"{name}: the table's description differs from {path}'s:\n  table:    {description}\n  manifest: {want}")
        deps = {d[len("alba-"):] for d in manifest.get("dependencies", {}) if d.startswith("alba-")}
        if uses == "all":
            continue
        listed = set() if uses == "—" else {u.strip() for u in uses.split(",")}
        if listed != deps:
            errors.append(
                f"{name}: uses {', '.join(sorted(deps)) or '—'} (manifest), the table says {uses}"
            )
    for name in rows:
        errors.append(f"docs/ARCHITECTURE.md: a row for {name}, which is not a crate under crates/")
    # The HTTP crate is only the API (ADR 0014): the control layer, the compiler's
    # API types, the IR and the users, at most six workspace crates.
    if "alba-server" in crates:
        server = [d for d in crates["alba-server"][1].get("dependencies", {}) if d.startswith("alba-")]
        if len(server) > MAX_SERVER_DEPS:
            errors.append(f"alba-server uses {len(server)} workspace crates ({', '.join(sorted(server))}), at most {MAX_SERVER_DEPS}")
    errors.extend(no_toml_under_the_compiler())
    for e in errors:
        print(f"error: {e}", file=sys.stderr)
    cycles = subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__), "check-module-cycles.py")])
    return 1 if errors or cycles.returncode else 0


def no_toml_under_the_compiler() -> list:
    """The compiler's normal dependencies hold no TOML crate (toml, toml_parser,
    toml_datetime, toml_edit, …): project files are read above it (ADR 0014)."""
    tree = None
    for offline in (["--offline"], []):
        r = subprocess.run(
            ["cargo", "tree", *offline, "-p", "alba-compiler", "-e", "normal", "--prefix", "none"],
            capture_output=True,
            text=True,
        )
        if r.returncode == 0:
            tree = r.stdout
            break
    if tree is None:
        return [f"cargo tree -p alba-compiler failed: {r.stderr.strip()}"]
    names = sorted({line.split()[0] for line in tree.splitlines() if line.strip()})
    if "alba-compiler" not in names:
        return ["cargo tree -p alba-compiler listed no alba-compiler: cannot check its dependencies"]
    toml = [n for n in names if "toml" in n]
    if toml:
        return [
            f"alba-compiler has {', '.join(toml)} under it (cargo tree -p alba-compiler -e normal): "
            "the alba.toml reader belongs above the compiler, in alba-load (ADR 0014)"
        ]
    return []


if __name__ == "__main__":
    sys.exit(main())
