"""The reference table of every registered cost and constraint term (``docs/terms.md``).

``python -m nmsm.testing.term_catalog > docs/terms.md`` rewrites it from the registry (name,
kind, tools, the class's one-line description and its settings elements).
"""

from __future__ import annotations

import warnings

from nmsm.core.registry import get_registry

_NOT_ELEMENTS = {"is_enabled", "name"}


def catalog() -> str:
    """Markdown: one table row per registered (kind, name, class)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        items = [it for it in get_registry().items() if it.kind in ("cost", "constraint")]
    lines = [
        "# Registered cost and constraint terms",
        "",
        "Every `<type>` a settings file may give in `<RCNLCostTerm>` / `<RCNLConstraintTerm>`, with the",
        "tools that accept it, what it computes and its settings elements (besides `is_enabled`, `name`).",
        "Written from the registry by `python -m nmsm.testing.term_catalog > docs/terms.md`; the tools'",
        "pages (treatment.md, gcp.md, mtp.md, ncp.md, jmp.md) explain the formulations. Plugins add",
        "their own names (`nmsm plugins` lists what is installed). `nmsm plugins --check` runs",
        "`nmsm.testing.check_term` on each (docs/plugins.md, 'Check it'). A term that differentiates",
        "(`ctx.differentiate`) a quantity depending on the controls gets a `DiscontinuousDerivativeWarning`",
        "(docs/plugins.md, 'Derivatives of the context'): `controller_slope_minimization` does.",
        "",
        "| type | kind | tools | description | elements |",
        "|---|---|---|---|---|",
    ]
    seen: set[tuple[str, str, type]] = set()
    for it in sorted(items, key=lambda i: (i.kind, i.name)):
        if it.distribution != "nmsm" or (it.kind, it.name, it.cls) in seen:
            continue
        seen.add((it.kind, it.name, it.cls))
        doc = (it.cls.__doc__ or "").strip().splitlines()[0] if it.cls.__doc__ else ""
        elements = ", ".join(f"`{e}`" for e in it.cls.xml_fields() if e not in _NOT_ELEMENTS)
        lines.append(f"| `{it.name}` | {it.kind} | {', '.join(sorted(it.tools))} | {doc.replace('|', '/')} | "
                     f"{elements} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(catalog(), end="")
