"""The report's sections are a table (issue 21 item 7): one module + one ``SECTIONS`` row adds a section."""

from __future__ import annotations

import sys
import types
from types import SimpleNamespace

import pytest

from fogdrift.errors import ConfigError
from fogdrift.report import html, sections


def test_the_table_names_real_functions_in_page_order():
    assert [s.key for s in sections.sections("recording")] == ["signal", "spectrum", "temperature"]
    assert [s.key for s in sections.sections("axis")] == ["gmwm", "noise", "separation", "compensation"]
    for s in sections.SECTIONS:
        assert callable(getattr(__import__(s.module, fromlist=["_"]), s.function)), s
        assert s.scope in sections.SCOPES and s.description
    with pytest.raises(ConfigError, match="scope"):
        sections.sections("page")


def test_a_new_row_is_rendered_without_touching_html(monkeypatch):
    mod = types.ModuleType("hs_fake_section")
    mod.render = lambda ax, result, fig_dir, pre, fig_offset, evaluated: f"<p>extra {ax.name} {pre}</p>"
    mod.nothing = lambda ax, *a: ""
    monkeypatch.setitem(sys.modules, "hs_fake_section", mod)
    rows = (sections.Section("extra", "axis", "hs_fake_section", "render", "test row"),
            sections.Section("empty", "axis", "hs_fake_section", "nothing", "a section that does not apply"))
    monkeypatch.setattr(sections, "SECTIONS", rows)
    out = html._axis_section(SimpleNamespace(name="g<x>"), None, None, "apply_to_", 2, True)
    assert out.splitlines() == ['<section id="apply_to_axis-g_x"><h2>Applied: Axis g&lt;x&gt;</h2>',
                                "<h3>Noise identification (whole record, native rate)</h3>",
                                "<p>extra g<x> apply_to_</p>", "</section>"]
