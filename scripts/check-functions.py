#!/usr/bin/env python3
"""Fails when a function of the machine's folders (nodes/) or app/ is over 60 lines.

Reads each tracked .cpp and .hpp there with comments and string literals
blanked out, follows the braces, and classifies each opening brace by the
text since the previous `;`, `{` or `}`: a namespace, class, struct, enum or
union opens a scope; inside a scope (or at file level), text with a `)` opens
a function, counted from its signature's first line to its closing brace;
anything else is a block within the function. Lambdas count as part of the
function they are written in.

usage: check-functions.py [--limit N] [--list]
  --limit N  the most lines a function may take (default 60)
  --list     print every function's length, longest first
Exit 0 when none is over the limit, 1 otherwise (each named with file:line).
"""
import argparse
import re
import subprocess
import sys

SCOPE = re.compile(r"\b(namespace|class|struct|enum|union)\b|extern\s*\"")


def blank(text):
    """The text with comments, string and character literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'" and not (c == "'" and i > 0 and text[i - 1].isalnum()):  # 1'000 is a digit separator
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(first line, last line, signature) of each function defined in the file."""
    text = blank(open(path, encoding="utf-8").read())
    found, stack = [], []  # stack: (kind, first line) per open brace
    statement_start, line = 0, 1
    pending = []
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        if c in ";{}":
            head = "".join(pending)
            if c == "{":
                in_scope = not stack or stack[-1][0] == "scope"
                if SCOPE.search(head) and ")" not in head:
                    kind = "scope"
                elif in_scope and ")" in head:
                    kind = "function"
                else:
                    kind = "block"
                stack.append((kind, statement_start, head.strip()))
            elif c == "}" and stack:
                kind, first, head = stack.pop()
                if kind == "function":
                    found.append((first, line, " ".join(head.split())[:80]))
            pending = []
            statement_start = line + (1 if text[i + 1:i + 2] == "\n" else 0)
        else:
            if not pending and c.isspace():
                if c == "\n":
                    statement_start = line
                continue
            if not pending:
                statement_start = line
            pending.append(c)
    return found


def main():
    parser = argparse.ArgumentParser(usage=__doc__.split("usage: ")[1].split("\n")[0])
    parser.add_argument("--limit", type=int, default=60)
    parser.add_argument("--list", action="store_true")
    args = parser.parse_args()
    files = subprocess.run(["git", "ls-files", "nodes", "app"], capture_output=True, text=True,
                           check=True).stdout.split()
    lengths = []
    for path in files:
        if path.endswith((".cpp", ".hpp")):
            for first, last, head in functions(path):
                lengths.append((last - first + 1, path, first, head))
    lengths.sort(reverse=True)
    over = [f for f in lengths if f[0] > args.limit]
    for n, path, first, head in (lengths if args.list else over):
        print("%s:%d: %d lines: %s" % (path, first, n, head))
    print("check-functions: %d function(s) over %d lines, of %d in nodes/ and app/" %
          (len(over), args.limit, len(lengths)))
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
