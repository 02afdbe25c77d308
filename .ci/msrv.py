#!/usr/bin/env python3
"""Check the workspace's `rust-version` claim against its dependencies.

Every package that a user's build of a workspace crate compiles (normal dependencies
with default features, for the host) must declare a `rust-version` no newer than the
workspace's. Our own code is checked by clippy's `incompatible_msrv` lint, which reads
the same `rust-version`.
"""
import json
import subprocess
import sys


def version(v):
    return tuple(int(x) for x in (v or "0").split("."))


meta = json.loads(
    subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--locked"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
)
by_id = {p["id"]: p for p in meta["packages"]}
members = [by_id[i] for i in meta["workspace_members"]]
claims = {p["rust_version"] for p in members}
if len(claims) != 1:
    sys.exit(f"msrv: workspace members disagree on rust-version: {sorted(claims)}")
msrv = claims.pop()

bad = []
for member in members:
    tree = subprocess.run(
        ["cargo", "tree", "--locked", "-e", "normal", "-p", member["name"], "--prefix", "none",
         "--format", "{p}"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    for line in tree.splitlines():
        parts = line.split()
        if len(parts) < 2:
            continue
        name, ver = parts[0], parts[1].lstrip("v")
        for p in meta["packages"]:
            if p["name"] == name and p["version"] == ver:
                if version(p.get("rust_version")) > version(msrv):
                    bad.append(f"{member['name']} -> {name} {ver} needs {p['rust_version']}")
if bad:
    sys.exit("msrv: rust-version " + msrv + " is not true:\n  " + "\n  ".join(sorted(set(bad))))
print(f"msrv: every normal dependency of the workspace builds with Rust {msrv}")
