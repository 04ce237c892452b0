"""Checks of reports/index.html as headless Chromium rendered it (tests/browser/check.sh).

usage: check_page.py PAGE.html DUMPED_DOM.html CONSOLE.log SCREENSHOT.png

* the page renders its tables: the number of <table> elements in the DOM Chromium dumped after
  loading the page is > 0 and equal to the number in the page's source;
* every <a href> and <img src> of the source is relative and names an existing file (relative
  to the page's folder) or an id of the page (#anchor);
* no image failed to load: the page's inline script ran (it writes data-images and
  data-broken-images on <body>) and marked no <img> with data-broken="true"
  (naturalWidth == 0 after the load event);
* no script error: Chromium's console log (--enable-logging=stderr) has no "Uncaught";
* the screenshot is a PNG file.
Exit 0 when all hold, 1 otherwise (each failure printed). Standard library only.
"""

import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote


class Collect(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tables = 0
        self.targets = []          # (tag, attribute, value)
        self.ids = set()
        self.broken = []
        self.body = {}

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "table":
            self.tables += 1
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and "href" in a:
            self.targets.append((tag, "href", a["href"]))
        if tag == "img":
            self.targets.append((tag, "src", a.get("src", "")))
            if a.get("data-broken") == "true":
                self.broken.append(a.get("src", ""))
        if tag == "body":
            self.body = a

    handle_startendtag = handle_starttag


def parse(text):
    c = Collect()
    c.feed(text)
    c.close()
    return c


def main(page_path, dom_path, console_path, shot_path):
    page_path, shot_path = Path(page_path), Path(shot_path)
    source = parse(page_path.read_text(encoding="utf-8"))
    dom = parse(Path(dom_path).read_text(encoding="utf-8", errors="replace"))
    console = Path(console_path).read_text(encoding="utf-8", errors="replace")
    problems = []
    if source.tables == 0:
        problems.append("the page source has no <table>")
    if dom.tables != source.tables:
        problems.append(f"the rendered DOM has {dom.tables} <table> elements, the page source "
                        f"{source.tables}")
    folder = page_path.parent
    for tag, attr, value in source.targets:
        if value.startswith("#"):
            if value[1:] not in source.ids:
                problems.append(f"<{tag} {attr}=\"{value}\">: no element with that id")
            continue
        path = unquote(value.split("#")[0])
        if not path or ":" in value or path.startswith("/") or ".." in Path(path).parts:
            problems.append(f"<{tag} {attr}=\"{value}\">: not a relative link into the folder")
        elif not (folder / path).is_file():
            problems.append(f"<{tag} {attr}=\"{value}\">: {folder / path} does not exist")
    images = dom.body.get("data-images")
    if images is None:
        problems.append("the page's script did not run (no data-images on <body> in the DOM)")
    elif int(images) != sum(1 for t in source.targets if t[0] == "img"):
        problems.append(f"the DOM counts {images} images, the page source "
                        f"{sum(1 for t in source.targets if t[0] == 'img')}")
    if dom.broken or dom.body.get("data-broken-images", "0") != "0":
        problems.append(f"images that failed to load: {dom.broken}")
    errors = [ln for ln in console.splitlines() if "Uncaught" in ln]
    if errors:
        problems.append("script errors: " + " | ".join(errors[:5]))
    if not shot_path.is_file() or shot_path.read_bytes()[:8] != b"\x89PNG\r\n\x1a\n":
        problems.append(f"no PNG screenshot at {shot_path}")
    for p in problems:
        print(f"browser: FAIL {p}")
    links = sum(1 for t in source.targets if t[0] == "a")
    if not problems:
        print(f"browser: pass: {dom.tables} tables rendered (of {source.tables} in the page), "
              f"{images} images loaded, {links} links and {len(source.targets) - links} image "
              f"sources resolve, no script errors; screenshot {shot_path}")
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 5:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        sys.exit(2)
    sys.exit(main(*sys.argv[1:]))
