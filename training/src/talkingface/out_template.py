"""The face template beside an export: the browser loads the face from OUT/template/ (the manifest's template.path),
so an export checks that what is there is its model's, and puts the template's files there where it is missing."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

from .template import Template, TemplateFormatError


def check_out_template(out: Path, template: Template) -> None:
    """The browser loads the face from OUT/template/template.json: where one is there, it must be this model's."""
    there = out / "template" / "template.json"
    if there.exists() and (other := json.loads(there.read_text()).get("id")) != template.id:
        raise TemplateFormatError(f"{there} is template {other!r}, but the model was trained on {template.id!r}: "
                         "export to another folder, or put the model's template there")


def copy_template(source: Path | None, out: Path) -> str | None:
    """The browser reads the face from OUT/template/ (the manifest's template.path): where it is not there yet, the
    template's own files go there (its template.json with its template.bin, and a NOTICE beside them). Says what it
    did, or what is missing; None where OUT already has it."""
    there = out / "template" / "template.json"
    if there.exists():
        return None
    if source is None or source.suffix != ".json" or not source.with_suffix(".bin").exists():
        return (f"note: {there} is missing, and the browser loads the face from there: put the template's template.json "
                "and template.bin there (npm run import-template makes them from a mesh; docs/templates.md)")
    there.parent.mkdir(parents=True, exist_ok=True)
    for f in (source, source.with_suffix(".bin"), source.parent / "NOTICE"):
        if f.exists():
            shutil.copyfile(f, there.parent / f.name)
    return f"copied the face template ({source.parent}) to {there.parent}"
