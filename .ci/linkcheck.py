"""Every relative link of the built book leads somewhere: a page of the book and the
anchor it names, or a file of the repository (the pages link results/, examples/ and
tests/ by relative path, which resolve from the page's source in docs/src).

    python3 .ci/linkcheck.py docs/book docs/src
"""

import pathlib
import sys
import urllib.parse
from html.parser import HTMLParser


class Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids = set()
        self.links = []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name == "id" and value:
                self.ids.add(value)
            if value and ((tag == "a" and name == "href") or (tag == "img" and name == "src")):
                self.links.append(value)


def parse(path):
    page = Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


def main(book, src):
    book, src = pathlib.Path(book).resolve(), pathlib.Path(src).resolve()
    pages = {p: parse(p) for p in book.rglob("*.html")}
    # print.html repeats every page with its links rewritten; toc.html and 404.html are
    # mdbook's own.
    checked = [p for p in pages if p.name not in ("print.html", "toc.html", "404.html")]
    broken = []
    count = 0
    for page in checked:
        for link in pages[page].links:
            parts = urllib.parse.urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith("mailto:"):
                continue
            count += 1
            path = urllib.parse.unquote(parts.path)
            target = (page.parent / path).resolve() if path else page
            if target.is_relative_to(book):
                if not target.exists():
                    broken.append(f"{page.relative_to(book)}: {link}: no such page")
                elif parts.fragment and target.suffix == ".html":
                    if parts.fragment not in pages[target].ids:
                        broken.append(f"{page.relative_to(book)}: {link}: no such anchor")
            else:
                # Outside the book: the repository file, from the page's source folder.
                source_dir = src / page.parent.relative_to(book)
                if not (source_dir / path).resolve().exists():
                    broken.append(f"{page.relative_to(book)}: {link}: no such file")
    if count < 100:
        broken.append(f"only {count} links found: is {book} the built book?")
    for b in broken:
        print(b, file=sys.stderr)
    print(f"{count} links in {len(checked)} pages checked, {len(broken)} broken")
    return 1 if broken else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python3 .ci/linkcheck.py BOOK_DIR SRC_DIR")
    sys.exit(main(sys.argv[1], sys.argv[2]))
