"""HTML pages from the Jinja templates in ``templates/``, autoescaped: no text of a submission reaches a page
unescaped. A template's stylesheet and script are inlined (``{{ style("feedback.css") }}``, ``{{ script(...) }}``),
so every page is one file that makes no request."""

from __future__ import annotations

import functools
from importlib.resources import files

from markupsafe import Markup


@functools.cache
def environment():
    """The Jinja environment of labkit's templates: autoescape always on, undefined names an error."""
    import jinja2

    return jinja2.Environment(
        loader=jinja2.PackageLoader("labkit.grading", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )


def style(name: str) -> Markup:
    """A stylesheet or script of ``templates/`` as text to inline in a ``<style>`` or ``<script>`` element (labkit's
    own file, no input)."""
    text = files("labkit.grading").joinpath("templates", name).read_text(encoding="utf-8")
    return Markup(text.replace("</", "<\\/"))


script = style  # a script is inlined as a stylesheet is


def render(template: str, **values) -> str:
    """The page `template` of ``templates/`` filled with `values` (each escaped where it is shown)."""
    return environment().get_template(template).render(style=style, script=script, **values)
