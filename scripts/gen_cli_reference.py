"""Write docs/reference/cli.md: every command and flag, generated from the commands themselves (their --help).

Run by ``make docs`` before the site is built; ``tests/project/test_docs_site.py`` checks the page is current.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "reference" / "cli.md"


def render() -> str:
    import typer

    from fogdrift.cli import app

    group = typer.main.get_command(app)
    ctx = type(group).context_class(group, info_name="fogdrift")
    lines = ["# Command line reference", "",
             "Generated from the commands themselves (`scripts/gen_cli_reference.py`, run by `make docs`): every "
             "command and every flag, with its help text and default.", ""]
    for name in sorted(group.list_commands(ctx)):
        cmd = group.get_command(ctx, name)
        lines += [f"## fogdrift {name}", "", (cmd.help or "").strip().replace("\b\n", ""), ""]
        lines += ["| flag | type | default | help |", "| --- | --- | --- | --- |"]
        for p in cmd.params:
            if p.param_type_name == "argument":
                flag = f"`{p.name.upper()}` (argument)"
            else:
                flag = ", ".join(f"`{o}`" for o in list(p.opts) + list(p.secondary_opts))
            kind = p.display_type(ctx) if callable(getattr(p, "display_type", None)) else ""
            kind = str(kind).strip("<>")
            default = "" if p.default is None or callable(p.default) else f"`{p.default}`"
            text = (getattr(p, "help", "") or "").replace("|", "\\|").replace("\n", " ")
            lines.append(f"| {flag} | {kind} | {default} | {text} |")
        lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    text = render()
    if sys.argv[1:2] == ["--check"]:
        sys.exit(0 if OUT.is_file() and OUT.read_text(encoding="utf-8") == text else 1)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(text, encoding="utf-8")
    print(f"wrote {OUT.relative_to(ROOT)}")
