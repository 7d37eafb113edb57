"""The commented batch file of ``nmsm print-xml batch`` (docs/batch.md)."""

from __future__ import annotations

BATCH_TEMPLATE = """<?xml version="1.0" encoding="UTF-8"?>
<!-- A batch of nmsm runs (nmsm batch BATCH.xml; docs/batch.md). Relative paths are relative to this
     file's folder; every worker must see the inputs and the results folder at the same paths. -->
<NMSMPipelineDocument Version="1.5.3">
  <BatchTool name="cohort">
    <!-- The results folder: one folder per run (<run>/, <sweep>/<variant>/), each run's settings as
         run (<run>.xml), batch_summary.csv, plots/sweep_<name>.png. Required (or nmsm batch -o). -->
    <results_directory>batch_results</results_directory>
    <RunList>
      <!-- <Run name="...">: one run. Exactly one of
             <settings_file>: a tool's settings file, run as nmsm run would (JMP, MTP, NCP, GCP, TO, VO, DO,
                              and the pipeline's own analysis, preprocessing and surrogate-data tools);
             <pipeline_file>: a pipeline file, run as nmsm pipeline would (its stages kept up to date).
           Optional: patient="..." (a column of the summary);
             <depends_on>: names of runs or sweeps this run waits for (a sweep: all its variants);
             <warm_start_from>: a run (or sweep/variant, or pipeline-run/stage) whose results folder becomes
                                this run's <initial_guess_directory> (TO, VO, DO); the run waits for it;
             <results_directory>: its folder inside the batch's results folder (default: its name). -->
      <Run name="P01" patient="P01">
        <pipeline_file>P01/pipeline.xml</pipeline_file>
      </Run>
      <!-- <Sweep name="...">: one run per variant of a settings file. Each <Parameter> names one or more
           settings elements (ElementPath below the tool element: tags separated by '/', [k] for the k-th,
           [tag='text'] or [@attribute='value'] to pick one; each path must match exactly one element
           holding a value) that all take the parameter's value.
           Values: <values>v1 v2 ...</values> on every parameter (every combination runs: a grid; a value
           with spaces: <values><value>0.5 0.5</value>...</values>), or instead one <Variant name="...">
           per run giving <parameter name>value</parameter name> for each parameter. -->
      <Sweep name="P01_weakness" patient="P01">
        <settings_file>P01/do.xml</settings_file>
        <warm_start_from>P01/vo</warm_start_from>
        <Parameter name="strength">
          <element>RCNLParameterTermSet/RCNLParameterTerm[type='max_isometric_force_scale']/initial_values</element>
          <element>RCNLParameterTermSet/RCNLParameterTerm[type='max_isometric_force_scale']/lower_bounds</element>
          <element>RCNLParameterTermSet/RCNLParameterTerm[type='max_isometric_force_scale']/upper_bounds</element>
          <values>0.6 0.7 0.8 0.9 1.0</values>
        </Parameter>
        <Parameter name="tracking_error">
          <element>RCNLCostTermSet/RCNLCostTerm[type='controller_tracking']/max_allowable_error</element>
          <values>0.5 1</values>
        </Parameter>
      </Sweep>
    </RunList>
  </BatchTool>
</NMSMPipelineDocument>
"""
