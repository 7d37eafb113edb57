"""Ground Contact Personalization (GCP) cost terms (docs/terms.md, docs/gcp.md), one module per family.

Each term asks :class:`nmsm.tools.gcp.context.GcpContext` for one raw block per foot; the
base class normalizes each block, ``(raw - error_center) / max_allowable_error``, and GCP
reduces each to ``z / sqrt(len(z))``.
"""
