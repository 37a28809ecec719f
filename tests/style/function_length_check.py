#!/usr/bin/env python3
"""function_length_check.py SOURCE_DIR MAX_LINES FOLDER...: fails, naming each
one, when a function defined in a C++ file under the folders runs longer than
MAX_LINES lines, from the first line of its signature to its closing brace.

A small scanner, not a compiler: it follows braces outside comments, strings
and character literals, and reads the text before each opening brace at
namespace or class scope to tell a function body from a namespace, a class or
an initialiser. Lambdas and local classes count as part of their function."""
import pathlib
import re
import sys

SCOPE_WORDS = re.compile(r'\b(namespace|extern\s+"C")\b')
TYPE_WORDS = re.compile(r'\b(class|struct|union|enum)\b')


def strip_code(text):
    """The text with comments, strings and character literals blanked,
    newlines kept, so that braces and line numbers can be read off it."""
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
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i)
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum())):
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(" " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def long_functions(path, max_lines):
    """(first line, length, signature) of each function in the file longer
    than max_lines."""
    code = strip_code(path.read_text(errors="replace"))
    found = []
    stack = []  # ("scope" | "type" | "body", start line, signature)
    header_start = 0
    for i, c in enumerate(code):
        if c in ";{}":
            if c == "{":
                header = code[header_start:i]
                at_outer = all(kind in ("scope", "type") for kind, _, _ in stack)
                kind = "body"
                if at_outer:
                    flat = " ".join(header.split())
                    if SCOPE_WORDS.search(flat) and "(" not in flat:
                        kind = "scope"
                    elif TYPE_WORDS.search(flat) and "(" not in flat:
                        kind = "type"
                    elif "(" in flat and not flat.rstrip().endswith("="):
                        kind = "function"
                    else:
                        kind = "body"
                lead = len(header) - len(header.lstrip())
                start_line = code.count("\n", 0, header_start + lead) + 1
                stack.append((kind, start_line, " ".join(header.split())[:90]))
            elif c == "}" and stack:
                kind, start_line, signature = stack.pop()
                if kind == "function":
                    end_line = code.count("\n", 0, i) + 1
                    length = end_line - start_line + 1
                    if length > max_lines:
                        found.append((start_line, length, signature))
            header_start = i + 1
        elif c == ":" and stack and stack[-1][0] == "type":
            # "public:" and the like end a header inside a class.
            before = code[header_start:i].strip()
            if before in ("public", "private", "protected"):
                header_start = i + 1
    return found


def main():
    if len(sys.argv) < 4:
        sys.exit("usage: function_length_check.py SOURCE_DIR MAX_LINES FOLDER...")
    root = pathlib.Path(sys.argv[1])
    max_lines = int(sys.argv[2])
    files = sorted(p for folder in sys.argv[3:] for p in (root / folder).rglob("*")
                   if p.suffix in (".cpp", ".cc", ".h") and p.is_file())
    if not files:
        sys.exit(f"no C++ files under {', '.join(sys.argv[3:])} in {root}")
    bad = [(p, f) for p in files for f in long_functions(p, max_lines)]
    for p, (line, length, signature) in bad:
        print(f"{p.relative_to(root)}:{line}: {length} lines: {signature}")
    if bad:
        sys.exit(f"{len(bad)} functions longer than {max_lines} lines in {len(files)} files")
    print(f"{len(files)} files, no function longer than {max_lines} lines")


if __name__ == "__main__":
    main()
