#!/usr/bin/env python3
"""Sizes of capstan's code: the largest files, classes and functions.

    scripts/code-size.py                 # the working tree
    scripts/code-size.py --rev eae508f   # a commit (read with git show)

A brace counter that skips strings, characters and comments; a function is a
brace block opened after a ')' (and optional qualifiers) at namespace or class
level, a class a block opened after 'class NAME' or 'struct NAME'. Lambdas and
blocks inside functions count towards their function. Lines are physical lines
from the opening line to the closing brace.
"""
import argparse
import re
import subprocess
from pathlib import Path

DIRS = ("src", "drivers", "kernels")


def files(rev):
    if rev:
        out = subprocess.run(["git", "ls-tree", "-r", "--name-only", rev, *DIRS], capture_output=True, text=True,
                             check=True).stdout.split()
        return {f: subprocess.run(["git", "show", f"{rev}:{f}"], capture_output=True, text=True).stdout
                for f in out if f.endswith((".cpp", ".hpp", ".h"))}
    return {str(p): p.read_text() for d in DIRS for p in sorted(Path(d).rglob("*")) if p.suffix in (".cpp", ".hpp", ".h")}


def strip(text):
    """The text with strings, chars and comments blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i)); i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = ")" + m.group(1) + '"'
            j = text.find(end, i) + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (j + 1 - i)); i = j + 1
        else:
            out.append(c); i += 1
    return "".join(out)


def blocks(text):
    """(kind, name, lines) of every class and function block."""
    s = strip(text)
    stack, found = [], []  # stack of (kind, name, start line)
    for i, c in enumerate(s):
        if c == "{":
            head = s[max(0, s.rfind(";", 0, i), s.rfind("}", 0, i), s.rfind("{", 0, i)) + 1:i]
            head = re.sub(r"\s+", " ", head).strip()
            outer = [k for k, _, _ in stack]
            kind, name = "block", ""
            m = re.search(r"\b(class|struct)\s+(\w+)[^()]*$", head)
            if "function" not in outer and m and "=" not in head.split(m.group(0))[-1]:
                kind, name = "class", m.group(2)
            elif "function" not in outer and re.search(r"\)\s*(const|override|noexcept|final|->\s*[\w:<>,\s*&]+|:\s*.*)?\s*$", head) \
                    and not re.match(r"^(if|for|while|switch|catch|namespace)\b", head) and "(" in head:
                kind = "function"
                m = re.search(r"([\w:~]+)\s*\(", head)
                name = m.group(1) if m else head[:40]
            stack.append((kind, name, s.count("\n", 0, i) + 1))
        elif c == "}" and stack:
            kind, name, start = stack.pop()
            if kind in ("class", "function"):
                found.append((kind, name, s.count("\n", 0, i) + 1 - start + 1))
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rev", help="a commit instead of the working tree")
    ap.add_argument("--top", type=int, default=5)
    a = ap.parse_args()
    fs = files(a.rev)
    sizes = sorted(((t.count("\n"), f) for f, t in fs.items()), reverse=True)
    cls, fun, body, methods = [], [], {}, {}
    for f, t in fs.items():
        for kind, name, n in blocks(t):
            (cls if kind == "class" else fun).append((n, f"{name} ({f})"))
            if kind == "class":
                body[name] = body.get(name, 0) + n
            elif "::" in name:
                owner = name.split("::")[-2]
                methods[owner] = methods.get(owner, 0) + n
    # A class with the methods it defines out of line: what one reads to know it.
    whole = sorted(((n + methods.get(c, 0), c) for c, n in body.items()), reverse=True)
    print(f"{a.rev or 'working tree'}: {len(fs)} files, {sum(n for n, _ in sizes)} lines in {', '.join(DIRS)}")
    for title, rows in (("files", sizes), ("class definitions", sorted(cls, reverse=True)),
                        ("classes with their out-of-line methods", whole), ("functions", sorted(fun, reverse=True))):
        print(f"largest {title}:")
        for n, what in rows[: a.top]:
            print(f"  {n:6d}  {what}")


if __name__ == "__main__":
    main()
