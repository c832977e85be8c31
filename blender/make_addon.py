#!/usr/bin/env python3
"""Makes the Blender add-on zip: blender/rsmooth_blender/ with the rsmooth package vendored in
rsmooth_blender/_vendor/rsmooth/, unpacked from one or more rsmooth wheels.

    python3 blender/make_addon.py WHEEL... [-o OUT.zip | -o DIR/]

Every wheel must be the same rsmooth version with the same Python files; their extension modules
(_rsmooth.abi3.so, _rsmooth.cpython-310-x86_64-linux-gnu.so, ...) all go in, side by side, so
each Blender's Python picks the one it can load: a version-specific module before abi3. bl_info's
version is set to the wheels' version. Standard library only; the zip is reproducible (sorted
entries, fixed times). Prints the zip's path, size and what each extension needs of glibc.
"""

from __future__ import annotations

import argparse
import hashlib
import io
import os
import re
import sys
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ADDON = "rsmooth_blender"
WHEEL_NAME = re.compile(r"^rsmooth-(?P<version>[0-9][^-]*)-(?P<tags>.+)\.whl$")
EPOCH = (1980, 1, 1, 0, 0, 0)


def fail(message: str) -> None:
    print(f"make_addon.py: {message}", file=sys.stderr)
    sys.exit(1)


def glibc_needed(data: bytes) -> str:
    """The newest GLIBC_x.y symbol version an ELF file names (its version-needs strings)."""
    found = {tuple(int(p) for p in m.split(b".")) for m in re.findall(rb"GLIBC_(2\.[0-9]+)", data)}
    return "2.%d" % max(found)[1] if found else "none"


def read_wheels(paths: list[str]) -> tuple[str, dict[str, bytes], dict[str, tuple[bytes, str]]]:
    """(version, {python file's name: bytes}, {extension's name: (bytes, wheel)}), each name
    relative to rsmooth/."""
    version = None
    python_files: dict[str, bytes] = {}
    extensions: dict[str, tuple[bytes, str]] = {}
    licence = None
    for path in paths:
        name = os.path.basename(path)
        m = WHEEL_NAME.match(name)
        if not m:
            fail(f"{path}: not an rsmooth wheel's name (rsmooth-VERSION-TAGS.whl)")
        if version is not None and m["version"] != version:
            fail(f"{path}: version {m['version']}, but an earlier wheel is {version}")
        version = m["version"]
        files: dict[str, bytes] = {}
        with zipfile.ZipFile(path) as z:
            for info in z.infolist():
                if info.is_dir():
                    continue
                if info.filename.startswith("rsmooth/"):
                    files[info.filename[len("rsmooth/"):]] = z.read(info)
                elif info.filename.endswith(".dist-info/licenses/LICENSE") and licence is None:
                    licence = z.read(info)
        exts = {f: d for f, d in files.items() if f.startswith("_rsmooth.") and f.endswith(".so")}
        if not exts:
            fail(f"{path}: no compiled extension (rsmooth/_rsmooth.*.so)")
        pure = {f: d for f, d in files.items() if f not in exts}
        if python_files and pure != python_files:
            fail(f"{path}: its Python files differ from the other wheels' (not one source tree)")
        python_files = pure
        for f, d in exts.items():
            if f in extensions and extensions[f][0] != d:
                print(f"make_addon.py: {name}: {f} also in {extensions[f][1]}; keeping that one")
                continue
            extensions.setdefault(f, (d, name))
    if licence is not None:
        python_files["LICENSE"] = licence
    assert version is not None
    return version, python_files, extensions


def addon_sources(version: str) -> dict[str, bytes]:
    """The add-on's own files, bl_info's version set to `version` (rsmooth's)."""
    folder = os.path.join(HERE, ADDON)
    out = {}
    for name in sorted(os.listdir(folder)):
        if not name.endswith((".py", ".toml")):
            continue
        with open(os.path.join(folder, name), "rb") as f:
            data = f.read()
        if name == "__init__.py":
            parts = re.fullmatch(r"(\d+)\.(\d+)\.(\d+)", version)
            if not parts:
                fail(f"version {version!r} is not MAJOR.MINOR.PATCH")
            data, n = re.subn(rb'"version": \(\d+, \d+, \d+\)',
                              b'"version": (%s, %s, %s)' % tuple(p.encode() for p in parts.groups()),
                              data)
            if n != 1:
                fail("rsmooth_blender/__init__.py: bl_info's \"version\" line not found")
        out[name] = data
    return out


def write_zip(out: str, entries: dict[str, bytes]) -> None:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as z:
        for name in sorted(entries):
            info = zipfile.ZipInfo(name, EPOCH)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = (0o755 if name.endswith(".so") else 0o644) << 16
            z.writestr(info, entries[name])
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "wb") as f:
        f.write(buffer.getvalue())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("wheels", nargs="+", metavar="WHEEL")
    parser.add_argument("-o", "--output", default="dist/",
                        help="the zip, or a folder ending in / for rsmooth_blender-VERSION.zip "
                        "in it (default dist/)")
    args = parser.parse_args()
    version, python_files, extensions = read_wheels(args.wheels)
    out = args.output
    if out.endswith("/") or os.path.isdir(out):
        out = os.path.join(out, f"{ADDON}-{version}.zip")
    entries = {f"{ADDON}/{name}": data for name, data in addon_sources(version).items()}
    vendored = f"{ADDON}/_vendor/rsmooth/"
    for name, data in python_files.items():
        entries[vendored + name] = data
    lines = [f"rsmooth {version}, unpacked from these wheels by blender/make_addon.py:"]
    for name, (data, wheel) in sorted(extensions.items()):
        entries[vendored + name] = data
        lines.append(f"  {name}: from {wheel}, sha256 {hashlib.sha256(data).hexdigest()}, "
                     f"needs glibc {glibc_needed(data)}")
    entries[f"{ADDON}/_vendor/VENDORED.txt"] = ("\n".join(lines) + "\n").encode()
    write_zip(out, entries)
    print(f"{out}: {os.path.getsize(out)} bytes ({os.path.getsize(out) / 1024:.0f} KiB), "
          f"rsmooth {version}")
    for line in lines[1:]:
        print(line)


if __name__ == "__main__":
    main()
