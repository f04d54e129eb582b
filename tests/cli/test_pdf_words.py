"""report.pdf: table cells break lines only between words, and no table runs off the page (issue 20).

Independent check: the PDF printed by headless Chromium is read back with PDFium (pypdfium2, the renderer of
Chromium's own PDF viewer).  Every word of every table cell of report.html must come back whole from the
PDF's text (a cell squeezed with ``overflow-wrap: anywhere`` printed ``axi|s``, ``MAS|E``, ``persiste|nce``), and
every character must lie inside the A4 page's 12 mm margins (a table wider than the page would be cut off).
"""

from __future__ import annotations

import re
import shutil
from html.parser import HTMLParser

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.simulate import simulate

pytestmark = [pytest.mark.slow, pytest.mark.browser]  # one analysis + one Chromium print: about 20 s
runner = CliRunner()
#: A4 in points and the report's print margin (12 mm = 34.0 pt), from the report's CSS ``@page``.
A4_PT = (595.3, 841.9)
MARGIN_PT = 12.0 / 25.4 * 72.0
#: Words are runs of letters (hyphens, digits, spaces and brackets are line-break places or not words).
WORD = re.compile(r"[^\W\d_]+")


class _Text(HTMLParser):
    """Visible text of an HTML page (no <style>, <title> or <script>), and the text of every <th>/<td>."""

    def __init__(self):
        super().__init__()
        self.skip, self.depth, self.words, self.cells = 0, 0, [], []

    def handle_starttag(self, tag, attrs):
        self.skip += tag in ("style", "title", "script")
        if tag in ("th", "td"):
            self.depth += 1
            self.cells.append("")

    def handle_endtag(self, tag):
        self.skip -= tag in ("style", "title", "script")
        self.depth -= tag in ("th", "td")

    def handle_data(self, data):
        if not self.skip:
            self.words += WORD.findall(data)
            if self.depth:
                self.cells[-1] += data


@pytest.fixture(scope="module")
def small_report(tmp_path_factory):
    if shutil.which("chromium") is None and shutil.which("chromium-browser") is None \
            and shutil.which("google-chrome") is None:
        pytest.skip("headless Chromium not installed (CI installs Debian's chromium)")
    tmp = tmp_path_factory.mktemp("pdfwords")
    n, dt_s = 60_000, 0.01
    rate_dph = simulate(n, dt_s, arw_dprh=0.05, bias_instability_dph=0.3, bias_dph=5.0, seed=1)
    log = tmp / "sim.csv"
    np.savetxt(log, np.column_stack([np.arange(n) * dt_s, rate_dph]), delimiter=",", header="t_s,gz",
               comments="", fmt="%.6f")
    result = runner.invoke(app, ["analyze", str(log), "--unit", "deg/h", "--no-heading", "--models", "ar,persistence",
                                 "--pdf", "--out", str(tmp / "out")])
    assert result.exit_code == 0, result.output + repr(result.exception)
    return tmp / "out"


def _pdf_pages(path):
    pdfium = pytest.importorskip("pypdfium2")
    doc = pdfium.PdfDocument(str(path))
    try:
        pages = []
        for i in range(len(doc)):
            page = doc[i]
            tp = page.get_textpage()
            boxes = [tp.get_charbox(k) for k in range(tp.count_chars())]
            pages.append((page.get_size(), tp.get_text_range(), [b for b in boxes if b[2] > b[0]]))
        return pages
    finally:
        doc.close()


def test_table_words_come_back_whole_from_the_pdf(small_report):
    html = _Text()
    html.feed((small_report / "report.html").read_text(encoding="utf-8"))
    pages = _pdf_pages(small_report / "report.pdf")
    pdf_words = [w for _, text, _ in pages for w in WORD.findall(text)]
    # a word cut inside a cell leaves pieces ('axi', 'MAS', 'persiste', 'nce') that are no word of the HTML
    pieces = sorted(set(pdf_words) - set(html.words))
    assert not pieces, f"PDF words that are not words of report.html (broken in a line?): {pieces}"
    # and the words come back whole as often as the tables hold them
    cell_words = [w for c in html.cells for w in WORD.findall(c)]
    for word in ("axis", "MASE", "persistence"):
        assert cell_words.count(word) >= 1, word  # the report's tables do hold them
        assert pdf_words.count(word) >= html.words.count(word), word


def test_pdf_text_stays_inside_the_page_margins(small_report):
    pages = _pdf_pages(small_report / "report.pdf")
    assert len(pages) >= 3
    for i, ((w, h), _, boxes) in enumerate(pages):
        assert (w, h) == pytest.approx(A4_PT, abs=1.0), i  # portrait A4, the report's @page
        if boxes:
            assert min(b[0] for b in boxes) >= MARGIN_PT - 1.0, i
            assert max(b[2] for b in boxes) <= w - MARGIN_PT + 1.0, i
