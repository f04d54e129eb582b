"""The documentation site's sources are current (issue 38): the CLI reference page is what the commands say now,
and every page the navigation names exists.  (`make docs` builds the site with mkdocs --strict in CI.)"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_cli_reference_is_generated_from_the_current_commands():
    res = subprocess.run([sys.executable, str(ROOT / "scripts" / "gen_cli_reference.py"), "--check"], cwd=ROOT,
                         capture_output=True, text=True)
    assert res.returncode == 0, ("docs/reference/cli.md is stale: run `python scripts/gen_cli_reference.py`\n"
                                 + res.stderr)


def test_the_cli_reference_lists_every_command_and_flag():
    import typer

    from fogdrift.cli import app

    text = (ROOT / "docs" / "reference" / "cli.md").read_text(encoding="utf-8")
    group = typer.main.get_command(app)
    ctx = type(group).context_class(group, info_name="fogdrift")
    for name in group.list_commands(ctx):
        assert f"## fogdrift {name}\n" in text
        for p in group.get_command(ctx, name).params:
            for opt in getattr(p, "opts", ()):
                if opt.startswith("-"):
                    assert f"`{opt}`" in text, (name, opt)


def test_every_page_of_the_navigation_exists():
    nav = re.findall(r":\s*([\w./-]+\.md)\s*$", (ROOT / "mkdocs.yml").read_text(encoding="utf-8"), flags=re.M)
    assert len(nav) > 20
    missing = [p for p in nav if not (ROOT / "docs" / p).is_file()]
    assert missing == []
