"""Neural Control Personalization (NCP) cost terms (docs/terms.md, docs/ncp.md), one module per term.

Each term asks :class:`nmsm.tools.ncp.context.NcpContext` for its raw quantity; the
base class normalizes it and NCP reduces it to ``raw / e / sqrt(numel(raw))``.
"""
