#!/usr/bin/env python3
"""stub_library.py REAL OUT: a shared library with REAL's SONAME and symbol versions whose every
exported function returns a pointer to zeros and whose every exported object is zeros.

tools/real-gpu-bundle.sh puts these in place of the libraries OpenImageIO links for formats
shadowlab never reads (video, GIS, DICOM, ...), so the binaries travel to a machine without
Debian's packages in a bundle small enough to copy. Their libraries bind every symbol at load
time, so an empty stub would not load; a call into a stub would return garbage, which is why
only formats shadowlab does not use are stubbed."""
import re
import subprocess
import sys
import tempfile

real, out = sys.argv[1], sys.argv[2]
soname = re.search(r"SONAME\s+(\S+)", subprocess.run(["objdump", "-p", real], capture_output=True, text=True,
                                                     check=True).stdout).group(1)
listing = subprocess.run(["nm", "-D", "--defined-only", "-S", real], capture_output=True, text=True, check=True)
asm, seen, versions = [".bss\n.balign 64\n__stub_zeros:\n .zero 4096\n"], set(), {}
for line in listing.stdout.splitlines():
    fields = line.split()
    if len(fields) < 3:
        continue
    full, kind = fields[-1], fields[-2]
    name, version = full.split("@")[0], (full.split("@")[-1] if "@" in full else None)
    size = int(fields[1], 16) if len(fields) == 4 else 0
    # Weak symbols (template instances, typeinfo of std types) stay with their real owners.
    if name in seen or kind not in "TiDBRGS":
        continue
    seen.add(name)
    versions.setdefault(version, []).append(name)
    if kind in "Ti":
        asm.append(f".text\n.globl {name}\n.type {name},@function\n{name}:\n lea __stub_zeros(%rip), %rax\n ret\n")
    else:
        size = max(size, 8)
        asm.append(f".bss\n.globl {name}\n.type {name},@object\n.size {name},{size}\n.balign 16\n{name}:\n"
                   f" .zero {size}\n")
with tempfile.NamedTemporaryFile("w", suffix=".s", delete=False) as source:
    source.write("".join(asm))
args = []
named = [v for v in versions if v]
if named:
    versions[named[0]] += versions.pop(None, [])
    with tempfile.NamedTemporaryFile("w", suffix=".map", delete=False) as script:
        for v in named:
            script.write(v + " {\n global:\n" + "".join(f'  "{n}";\n' for n in versions[v]) + "};\n")
    args = [f"-Wl,--version-script={script.name}"]
subprocess.run(["gcc", "-shared", "-nostdlib", "-o", out, source.name, f"-Wl,-soname,{soname}"] + args, check=True)
