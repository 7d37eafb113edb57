"""Preprocessing: raw EMG and OpenSim results -> the personalization folder layout.

``emg``        EMG filtering chain of the original (``processEmg``), MATLAB ``filtfilt``
``signals``    low-pass filtering and natural-quintic (GCV) resampling
``trials``     split IK / ID / GRF / EMG / muscle-analysis data into trials (``splitIntoTrials``)
``velocity``   muscle-tendon velocity from muscle-tendon length (``createMuscleTendonVelocity``)
``analyses``   IK / ID / MuscleAnalysis through nmsm's model core or OpenSim (bridge)
``settings``   the ``<PreprocessingTool>`` settings file read by ``nmsm preprocess``
``cli``        ``nmsm preprocess``
"""
