#!/usr/bin/env python3
"""Checks that every relative link and image in the repository's Markdown pages resolves.

    tools/check_links.py [--allow-missing PATH ...] [FILE.md ...]

Default files: README.md and every *.md under docs/ and scenes/. A link resolves when its
target (relative to the page) exists and, for `page.md#anchor` or `#anchor`, the target page
has a heading whose slug is that anchor (GitHub's and mdBook's rule: lower case, punctuation
dropped, spaces to hyphens, repeats numbered -1, -2, …). Links with a scheme (https:, mailto:)
are not fetched. Code blocks and code spans are skipped. --allow-missing names a
repository-relative page that is written elsewhere and may be absent for now; links to it are
listed as pending instead of failing. Exit status 1 if any link is broken.
"""

import argparse
import pathlib
import re
import sys

REPO = pathlib.Path(__file__).resolve().parent.parent

# [text](target) and ![alt](target); the target stops at whitespace or ')' (an optional
# "title" after a space is ignored).
LINK = re.compile(r"!?\[(?:[^\]\\]|\\.)*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(?:(?!\1).)+?\1")


def slug(heading: str) -> str:
    text = CODE_SPAN.sub(lambda m: m.group(0).strip("`"), heading.strip())
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)  # a link in a heading keeps its text
    text = text.lower()
    kept = "".join(c for c in text if c.isalnum() or c in " -_")
    return kept.replace(" ", "-")


def prose_lines(text: str):
    """(line number, line) of the lines outside fenced code blocks."""
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield number, line


def anchors(page: pathlib.Path, cache: dict) -> set:
    if page not in cache:
        seen: dict = {}
        found = set()
        for _, line in prose_lines(page.read_text(encoding="utf-8")):
            m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
            if not m:
                continue
            base = slug(m.group(2))
            n = seen.get(base, 0)
            seen[base] = n + 1
            found.add(base if n == 0 else f"{base}-{n}")
        cache[page] = found
    return cache[page]


def check(page: pathlib.Path, allowed: set, cache: dict):
    broken, pending, count = [], [], 0
    text = page.read_text(encoding="utf-8")
    for number, line in prose_lines(text):
        for match in LINK.finditer(CODE_SPAN.sub("", line)):
            target = match.group(1)
            if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):
                continue  # https:, mailto: …: not checked offline
            count += 1
            where = f"{page.relative_to(REPO)}:{number}"
            path_part, _, anchor = target.partition("#")
            dest = (page.parent / path_part).resolve() if path_part else page
            try:
                rel = dest.relative_to(REPO).as_posix()
            except ValueError:
                broken.append(f"{where}: {target} leaves the repository")
                continue
            if not dest.exists():
                if rel in allowed:
                    pending.append(f"{where}: {target} (pending: {rel})")
                else:
                    broken.append(f"{where}: {target} does not exist ({rel})")
                continue
            if anchor and dest.suffix == ".md" and anchor not in anchors(dest, cache):
                broken.append(f"{where}: {target}: no heading '#{anchor}' in {rel}")
    return broken, pending, count


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*", type=pathlib.Path)
    parser.add_argument("--allow-missing", action="append", default=[], metavar="PATH")
    args = parser.parse_args()
    files = [f.resolve() for f in args.files] or (
        [REPO / "README.md"]
        + sorted((REPO / "docs").rglob("*.md"))
        + sorted((REPO / "scenes").rglob("*.md"))
    )
    allowed = {pathlib.PurePosixPath(p).as_posix() for p in args.allow_missing}
    cache: dict = {}
    broken, pending, total = [], [], 0
    for page in files:
        if not page.exists():
            broken.append(f"{page}: no such file")
            continue
        b, p, n = check(page, allowed, cache)
        broken += b
        pending += p
        total += n
    for line in pending:
        print(line)
    for line in broken:
        print(f"BROKEN {line}", file=sys.stderr)
    print(f"{len(files)} pages, {total} relative links: {len(broken)} broken, {len(pending)} pending")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
