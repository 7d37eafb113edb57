"""One pipeline from lab data to treatment: ``nmsm pipeline``, ``nmsm example``, ``nmsm report``,
``nmsm export``.

Modules (one job each):

``pipeline_file``     reading ``PIPELINE.xml`` (docs/pipeline.md)
``kinds``             the stage kinds (tool elements), their order, inputs, outputs and wiring
``artifacts``         what stages hand to each other (model, osimx, data folders, results)
``stage_settings``    a stage's settings tree: path elements found, rewired, made absolute, hashed
``wiring``            rewriting a stage's inputs to earlier stages' outputs
``plan``              checks before running: stage order, every stage's inputs
``validation``        checks before running: each stage's settings as its tool reads them (terms too)
``hashing``           content digests of files and folders
``state``             ``pipeline_state.json``: records of finished stages; the stage-folder marker
``outputs``           where each kind of stage leaves its outputs
``runner``            running a pipeline, skipping up-to-date stages, resuming after a stop
``native``            reading the pipeline's own settings files (and ``nmsm run`` on them)
``analysis*``         the analysis stage: IK, ID and muscle analysis on the current model
``preprocess*``       the preprocessing stage: full-length trials cut into the tools' trials
``surrogate*``        the surrogate-data stage: sampled poses and their muscle analysis
``cli``               ``nmsm pipeline``, ``nmsm example``, ``nmsm report``, ``nmsm export``

Importing this package imports neither CasADi nor OpenSim.
"""
