"""The full-body gait case's prepared inputs, made once per case folder.

Each step writes into ``<folder>/prepared`` (or ``model``/``data``) and is skipped when its
output is there (steps write through a ``.partial`` folder renamed at the end, so a stopped
step leaves nothing that looks finished):

* ``model/fullbody.osim`` (:mod:`nmsm.examples.fullbody_model`);
* ``data/{IKData,IDData,GRFData}/gait_1.sto`` copied from the GCP tutorial, ``data/MAData``
  (``nmsm muscle-analysis`` of the 86 muscles on the 14 leg coordinates);
* ``prepared/gcp_r``, ``prepared/gcp_l``: GCP of each foot;
* stress case: ``prepared/static_optimization`` (synthetic activations), ``prepared/ncp``
  (NCP, 5 + 5 synergies), ``prepared/surrogate_stress`` (86 muscles x 14 coordinates) and
  ``prepared/fullbody_stress.osimx`` (NCP's osimx + both feet);
* combined case: ``prepared/surrogate_combined`` (the NCP tutorial's 9 muscles x 6
  right-leg coordinates) and ``prepared/fullbody_combined.osimx`` (the NCP tutorial's osimx
  + both feet).

Quick preparation (``quick=True``, for tests: about a minute instead of about ten): no GCP
runs - the GCP tutorial's right-foot result and its mirror image
(:func:`nmsm.examples.fullbody_gcp.write_mirrored_feet`, ``prepared/contact_mirrored``) -
and ``QUICK_SAMPLES_PER_FRAME`` surrogate poses per frame instead of ``nmsm surrogate``'s 25;
its artifacts carry ``_quick`` in their names.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import attrs
import numpy as np

from nmsm.examples import fullbody_data as fd
from nmsm.examples.fullbody_activations import (model_parameters, read_trial, static_optimization,
                                                tendon_slack_lengths, write_activations)
from nmsm.examples.fullbody_gcp import gcp_settings_xml, merge_contact, write_mirrored_feet
from nmsm.examples.fullbody_model import write_fullbody_model
from nmsm.examples.fullbody_ncp import ncp_settings_xml, write_muscle_osimx

#: the NCP tutorial's synergy-controller surrogate coordinates (the synergy kicking tutorial's)
COMBINED_SURROGATE = ("hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r",
                      "subtalar_angle_r")
STRESS_SYNERGIES = 5
#: surrogate poses per motion frame of quick cases (101 frames)
QUICK_SAMPLES_PER_FRAME = 3


def _log(message: str) -> None:
    print(f"[fullbody] {message}", file=sys.stderr, flush=True)


def _step(output: Path, what: str, make: Callable[[Path], None]) -> Path:
    """Run ``make(partial)`` unless ``output`` exists; ``partial`` is renamed to ``output``."""
    if output.exists():
        _log(f"{what}: {output} (kept)")
        return output
    partial = output.with_name(output.name + ".partial")
    if partial.is_dir():
        shutil.rmtree(partial)
    elif partial.exists():
        partial.unlink()
    start = time.perf_counter()
    _log(f"{what} ...")
    make(partial)
    os.replace(partial, output)
    _log(f"{what}: {output} ({time.perf_counter() - start:.1f} s)")
    return output


def _nmsm(*args: str) -> None:
    """Run an ``nmsm`` command in a child process (its output goes to this one's)."""
    subprocess.run([sys.executable, "-m", "nmsm", *args], check=True)


@attrs.frozen
class Prepared:
    """Absolute paths of a case folder's prepared inputs."""

    folder: Path

    @property
    def model(self) -> Path:
        return self.folder / "model" / "fullbody.osim"

    @property
    def data(self) -> Path:
        return self.folder / "data"

    def path(self, name: str) -> Path:
        return self.folder / "prepared" / name


def prepare_model(shared: fd.SharedInputs, prepared: Prepared) -> Path:
    return _step(prepared.model, "model (skeleton + 86 muscles)",
                 lambda out: write_fullbody_model(shared.body_model, shared.muscle_model, out))


def prepare_data(shared: fd.SharedInputs, prepared: Prepared) -> Path:
    def make(out: Path) -> None:
        for kind, source in (("IKData", shared.ik), ("IDData", shared.id), ("GRFData", shared.grf)):
            (out / kind).mkdir(parents=True)
            shutil.copy2(source, out / kind / source.name)
        _nmsm("muscle-analysis", str(prepared.model), str(out / "IKData" / f"{fd.TRIAL}.sto"),
              "--output", str(out / "MAData"), "--coordinates", *fd.muscle_coordinates())

    return _step(prepared.data, "data (IK, ID, GRF, muscle analysis)", make)


def prepare_gcp(shared: fd.SharedInputs, prepared: Prepared, side: str) -> Path:
    settings_folder = prepared.folder / "settings"
    output = prepared.path(f"gcp_{side}")

    def make(out: Path) -> None:
        settings_folder.mkdir(parents=True, exist_ok=True)
        path = settings_folder / f"GCPSettings_{side}.xml"
        path.write_text(gcp_settings_xml(shared.gcp_settings, settings_folder, side=side, model=prepared.model,
                                         preprocessed=shared.preprocessed, results=out), encoding="utf-8")
        # the tutorial's V4 tasks stop at their 20-iteration limit, as the original's do
        _nmsm("run", str(path), "--accept-unconverged")

    return _step(output, f"GCP of the {'right' if side == 'r' else 'left'} foot", make)


def _gcp_osimx(folder: Path) -> Path:
    found = sorted(folder.glob("*_gcp.osimx"))
    if len(found) != 1:
        raise FileNotFoundError(f"{folder}: expected one *_gcp.osimx, found {len(found)}")
    return found[0]


def prepare_stress_synergies(prepared: Prepared) -> Path:
    """Static optimization, personalized tendon slack lengths and NCP (5 + 5 synergies)."""
    from nmsm.model import load_model

    muscles = load_model(prepared.model).muscle_names
    coordinates = fd.muscle_coordinates()
    trial = read_trial(prepared.data, fd.TRIAL, coordinates, muscles)
    parameters = model_parameters(prepared.model, muscles)
    lengths = tendon_slack_lengths(trial, parameters)
    osimx = prepared.path("muscles.osimx")

    def make_so(out: Path) -> None:
        result = static_optimization(trial, attrs.evolve(parameters, tendon_slack_length=lengths), coordinates)
        write_activations(result, out, fd.TRIAL)
        rms = result.rms_error()
        (out / "summary.txt").write_text(
            "static optimization (synthetic activations), RMS moment error (N m):\n"
            + "".join(f"  {c:20s} {e:8.3f}\n" for c, e in zip(coordinates, rms)), encoding="utf-8")

    osimx.parent.mkdir(parents=True, exist_ok=True)
    if not osimx.exists():
        write_muscle_osimx(osimx, prepared.model, dict(zip(parameters.names, lengths)))
    activations = _step(prepared.path("static_optimization"), "static optimization (synthetic activations)", make_so)

    def make_ncp(out: Path) -> None:
        settings_folder = prepared.folder / "settings"
        settings_folder.mkdir(parents=True, exist_ok=True)
        path = settings_folder / "NCPSettings_stress.xml"
        path.write_text(ncp_settings_xml(settings_folder, model=prepared.model, osimx=osimx, data=prepared.data,
                                         activations=activations, results=out, synergies=STRESS_SYNERGIES),
                        encoding="utf-8")
        _nmsm("run", str(path))

    return _step(prepared.path("ncp"), "NCP (5 + 5 synergies)", make_ncp)


def prepare_surrogate(prepared: Prepared, name: str, model: Path, coordinates: tuple[str, ...], *,
                      samples_per_frame: int | None = None) -> Path:
    """Surrogate samples (``nmsm surrogate --motion ... --write-samples``) of ``model``
    (``samples_per_frame``: ``nmsm surrogate``'s default when None)."""
    fit = prepared.path(f"{name}_fit.json")

    def make(out: Path) -> None:
        if fit.exists():
            fit.unlink()
        extra = [] if samples_per_frame is None else ["--samples-per-frame", str(samples_per_frame)]
        _nmsm("surrogate", "--model", str(model), "--motion", str(prepared.data / "IKData" / f"{fd.TRIAL}.sto"),
              "--coordinates", *coordinates, "--write-samples", str(out), "-o", str(fit), *extra)

    return _step(prepared.path(name), f"surrogate samples ({name})", make)


def prepare_contact(shared: fd.SharedInputs, prepared: Prepared, quick: bool) -> list[Path]:
    """The ``.osimx`` of each foot's contact: GCP runs, or (``quick``) the tutorial's right
    foot and its mirror image."""
    if quick:
        folder = _step(prepared.path("contact_mirrored"), "contact: GCP tutorial's right foot and its mirror",
                       lambda out: write_mirrored_feet(shared.gcp_result, out))
        return [folder / "right_gcp.osimx", folder / "left_gcp.osimx"]
    return [_gcp_osimx(prepare_gcp(shared, prepared, side)) for side in fd.SIDES]


def merged_osimx(prepared: Prepared, name: str, synergy_osimx: Path, feet: list[Path]) -> Path:
    return _step(prepared.path(f"fullbody_{name}.osimx"), f"osimx with both feet ({name})",
                 lambda out: merge_contact(synergy_osimx, feet, out))


def max_synergy_activation(ncp_results: Path, headroom: float = 2.0) -> float:
    """Bound of the synergy controls: ``headroom`` times the largest NCP command after the
    controller's sum normalization (commands times their vector's sum), rounded up."""
    from nmsm.io.storage import read_storage

    weights = read_storage(ncp_results / "synergyWeights.sto")
    commands = read_storage(next(ncp_results.glob("*_synergyCommands.sto")))
    sums = weights.data.sum(axis=1)
    peak = float(np.max(commands.data.max(axis=0) * sums))
    return float(np.ceil(headroom * peak))
