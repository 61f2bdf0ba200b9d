#!/usr/bin/env python3
"""Checks every relative link of README.md and the user guide.

Usage: python3 docs/guide/check_links.py [ROOT]

Every Markdown link and image, `[text](target)` or `![alt](target)`,
outside code, in README.md and docs/guide/src/*.md: a target that is not
a URL must name a file or folder that exists, relative to the page, and
its `#anchor`, if any, must be the slug of a heading of the Markdown file
it names (or of the page itself for a bare `#anchor`). Slugs follow
GitHub's and mdBook's rule: the heading's text, formatting removed, in
lower case, keeping letters, digits, `-` and `_`, spaces made `-`; a
repeated slug gets `-1`, `-2`, ... Prints each broken link as
`FILE:LINE: message` and exits 1 if there is one. Python's own library
only.
"""

import os
import re
import sys

LINK = re.compile(r"!?\[((?:[^\[\]]|\[[^\]]*\])*)\]\(([^()\s]*(?:\([^()]*\))?[^()\s]*)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^\s*(```|~~~)")


def prose_lines(text):
    """(number, line) of the lines outside fenced code, inline code blanked."""
    inside = False
    for n, line in enumerate(text.split("\n"), 1):
        if FENCE.match(line):
            inside = not inside
            continue
        if inside:
            continue
        yield n, re.sub(r"`[^`]*`", lambda m: " " * len(m.group(0)), line)


def heading_text(line):
    """The text of an ATX heading line, or None."""
    m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
    if not m:
        return None
    text = m.group(2)
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)  # links: their text
    text = re.sub(r"<[^>]+>", "", text)  # inline HTML
    text = text.replace("`", "")
    text = re.sub(r"(\*\*|__|\*|_(?=\S)|(?<=\S)_)", lambda m: m.group(0) if m.group(0) == "_" else "", text)
    return text


def slug(text):
    out = []
    for ch in text.strip().lower():
        if ch.isalnum() or ch in "-_":
            out.append(ch)
        elif ch.isspace():
            out.append("-")
    return "".join(out)


_anchors = {}


def anchors(path):
    """The heading slugs of a Markdown file."""
    if path not in _anchors:
        seen = {}
        result = set()
        with open(path, encoding="utf-8") as f:
            text = f.read()
        inside = False
        for line in text.split("\n"):
            if FENCE.match(line):
                inside = not inside
                continue
            if inside:
                continue
            h = heading_text(line)
            if h is None:
                continue
            s = slug(h)
            if s in seen:
                seen[s] += 1
                s = f"{s}-{seen[s]}"
            else:
                seen[s] = 0
            result.add(s)
        # Explicit anchors: <a name="x"> or id="x".
        for m in re.finditer(r"<a\s+(?:name|id)=\"([^\"]+)\"", text):
            result.add(m.group(1))
        _anchors[path] = result
    return _anchors[path]


def check(page, root):
    problems = []
    with open(page, encoding="utf-8") as f:
        text = f.read()
    base = os.path.dirname(page)
    rel_page = os.path.relpath(page, root)
    count = 0
    for n, line in prose_lines(text):
        for m in LINK.finditer(line):
            target = m.group(2).strip("<>")
            if not target or re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
                continue  # a URL (http:, https:, mailto:, ...)
            count += 1
            path, _, anchor = target.partition("#")
            if path:
                full = os.path.normpath(os.path.join(base, path))
                if not os.path.exists(full):
                    problems.append(f"{rel_page}:{n}: `{target}`: {os.path.relpath(full, root)} does not exist")
                    continue
                if os.path.relpath(full, root).startswith(".."):
                    problems.append(f"{rel_page}:{n}: `{target}` points outside the repository")
                    continue
            else:
                full = page
            if anchor:
                if not full.endswith(".md") or os.path.isdir(full):
                    problems.append(f"{rel_page}:{n}: `{target}`: an anchor into a file that is not Markdown")
                elif anchor not in anchors(full):
                    problems.append(
                        f"{rel_page}:{n}: `{target}`: {os.path.relpath(full, root)} has no heading `#{anchor}`"
                    )
    return problems, count


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
    src = os.path.join(root, "docs", "guide", "src")
    pages = [os.path.join(root, "README.md")]
    pages += sorted(os.path.join(src, f) for f in os.listdir(src) if f.endswith(".md"))
    problems = []
    links = 0
    for p in pages:
        found, count = check(p, root)
        problems += found
        links += count
    for p in problems:
        print(p)
    print(f"check_links: {links} relative links in {len(pages)} pages, {len(problems)} broken")
    return 1 if problems or links == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
