#!/usr/bin/env python3
"""Regenerates every model's option table in docs/models/*.md from the code.

Usage: scripts/gen_option_docs.py [ATMOS_BINARY]   (default: build/atmos)

Between the lines `<!-- options:begin NAME -->` and `<!-- options:end NAME -->`
it writes the output of `atmos list NAME --markdown` (the model's OptionTable).
The test Docs.OptionTablesMatchTheCode fails when the docs and the code differ.
"""
import pathlib
import re
import subprocess
import sys

root = pathlib.Path(__file__).resolve().parent.parent
atmos = sys.argv[1] if len(sys.argv) > 1 else str(root / "build" / "atmos")
pattern = re.compile(r"(<!-- options:begin (\S+) -->\n)(.*?)(<!-- options:end \2 -->)", re.S)
for page in sorted((root / "docs" / "models").glob("*.md")):
    text = page.read_text()

    def table(m):
        md = subprocess.run([atmos, "list", m.group(2), "--markdown"], check=True,
                            capture_output=True, text=True).stdout
        return m.group(1) + md + m.group(4)

    new = pattern.sub(table, text)
    if new != text:
        page.write_text(new)
        print("updated", page.relative_to(root))
