"""Preprocessing: raw EMG and OpenSim results -> the personalization folder layout.

``emg``        EMG filtering chain of the original (``processEmg``), MATLAB ``filtfilt``
``tables``     input tables, every row (a wrong header ``nRows`` warns, as every reader)
``signals``    low-pass filtering, natural-quintic (GCV) resampling, gap-keeping interpolation
``trials``     split IK / ID / GRF / EMG / muscle-analysis data into trials (``splitIntoTrials``)
``velocity``   muscle-tendon velocity from muscle-tendon length (``createMuscleTendonVelocity``)
``analyses``   IK / ID / MuscleAnalysis through nmsm's model core or OpenSim (bridge)
``run``        one recording -> trials
``command``    the one checked path (``nmsm preprocess``, ``command.preprocess``, the pipeline's stage):
               arguments, output folder and inputs checked first, then ``run.process`` into a
               staging folder (``output``: no input's folder, no mixing of runs)
``cli``        ``nmsm preprocess``

Settings-file route: ``nmsm run`` on a ``<DataPreprocessingTool>`` file (the pipeline's
stage, :mod:`nmsm.tools.pipeline.preprocess_stage`, which calls this package); the
original has no preprocessing XML.
"""
