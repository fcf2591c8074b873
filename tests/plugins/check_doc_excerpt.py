#!/usr/bin/env python3
"""HapticsPlugin.DocExcerptMatchesCode: the C block of docs/haptics.md between
the "<!-- plug-in code: FILE -->" and "<!-- end of plug-in code -->" markers
is an excerpt of FILE: each of its lines (blank ones and "/* ... */"
elisions aside) is a line of FILE, in FILE's order, so the example a reader
copies is code the tests build and load.

usage: check_doc_excerpt.py SOURCE_DIR [PAGE]"""
import re
import sys


def main() -> int:
    source_dir = sys.argv[1]
    page_name = sys.argv[2] if len(sys.argv) > 2 else "docs/haptics.md"
    page = open(f"{source_dir}/{page_name}", encoding="utf-8").read()
    found = re.search(r"<!-- plug-in code: (\S+) -->\n```c\n(.*?)\n```\n<!-- end of plug-in code -->", page, re.S)
    if not found:
        print(f"{page_name}: no ```c block between the plug-in code's markers")
        return 1
    code_name, block = found.group(1), found.group(2)
    code = open(f"{source_dir}/{code_name}", encoding="utf-8").read().split("\n")
    at = 0
    shown = 0
    for number, line in enumerate(block.split("\n"), 1):
        if not line.strip() or line.strip().startswith("/* ..."):
            continue
        try:
            at = code.index(line, at) + 1
        except ValueError:
            print(f"{page_name}: line {number} of the plug-in code is not in {code_name} (after its line {at}):\n{line}")
            return 1
        shown += 1
    print(f"{page_name}: {shown} lines, all in {code_name} in its order")
    return 0


if __name__ == "__main__":
    sys.exit(main())
