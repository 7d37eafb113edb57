"""Treatment Optimization: tracking (TO), verification (VO) and design (DO) by direct collocation.

``run.run_settings(path, **options)`` is what ``nmsm run`` calls; ``context`` documents the
:class:`GridView` API that cost terms, constraints and controllers see; ``transcription`` holds
the collocation schemes. Nothing is imported here, so ``import nmsm.tools.treatment`` stays cheap.
"""
