"""Preprocessing: raw EMG and OpenSim results -> the personalization folder layout.

``emg``        EMG filtering chain of the original (``processEmg``), MATLAB ``filtfilt``
``tables``     input tables read as OpenSim's ``Storage`` reads them (header ``nRows``)
``signals``    low-pass filtering, natural-quintic (GCV) resampling, gap-keeping interpolation
``trials``     split IK / ID / GRF / EMG / muscle-analysis data into trials (``splitIntoTrials``)
``velocity``   muscle-tendon velocity from muscle-tendon length (``createMuscleTendonVelocity``)
``analyses``   IK / ID / MuscleAnalysis through nmsm's model core or OpenSim (bridge)
``run``        one recording -> trials (what ``nmsm preprocess`` runs)
``cli``        ``nmsm preprocess``

Settings-file route: ``nmsm run`` on a ``<DataPreprocessingTool>`` file (the pipeline's
stage, :mod:`nmsm.tools.pipeline.preprocess_stage`, which calls this package); the
original has no preprocessing XML (tools.md §2).
"""
