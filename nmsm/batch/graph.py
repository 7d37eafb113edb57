"""Which run waits for which: dependencies, warm starts, results folders.

``<depends_on>`` names runs or sweeps (a sweep: every one of its variants);
``<warm_start_from>`` names a run (or a sweep's variant, ``sweep/variant``), or a stage of a
pipeline run (``run/stage``), whose results folder becomes the run's initial guess; the run
waits for it too. :func:`link` refuses, before any run starts, a name that is no run, a
dependency cycle, and two runs whose results folders are the same or one inside the other.
"""

from __future__ import annotations

from pathlib import Path

import attrs

from nmsm.batch.batch_file import BatchSpec, Entry
from nmsm.batch.sweep import RunPlan


def _warm_start(spec: BatchSpec, entry: Entry, plans: dict[str, RunPlan],
                by_entry: dict[str, list[RunPlan]]) -> tuple[str, Path]:
    """``(parent run name, its results folder or the stage folder in it)``."""
    target = entry.warm_start_from
    assert target is not None
    if target in plans:
        return target, plans[target].folder
    head, _, stage = target.partition("/")
    runs = by_entry.get(head, [])
    if len(runs) == 1 and runs[0].kind == "pipeline" and stage:
        return runs[0].name, runs[0].folder / stage
    if len(runs) > 1:
        raise spec.error(f"'{entry.name}' starts from '{target}', a sweep of {len(runs)} runs", line=entry.line,
                         element="<warm_start_from>", expected="one run: a run's name or sweep/variant")
    if len(runs) == 1 and runs[0].kind == "pipeline":
        raise spec.error(f"'{entry.name}' starts from the pipeline run '{target}' without naming its stage",
                         line=entry.line, element="<warm_start_from>", expected=f"{target}/STAGE, e.g. {target}/vo")
    raise spec.error(f"'{entry.name}' starts from '{target}', which is no run of the batch", line=entry.line,
                     element="<warm_start_from>",
                     expected="a run's name, sweep/variant, or pipeline-run/stage; runs: " + ", ".join(by_entry))


def _cycle(depends: dict[str, tuple[str, ...]]) -> list[str] | None:
    """A dependency cycle (names, first repeated at the end), or None."""
    state: dict[str, int] = {}  # 1: on the path, 2: done
    path: list[str] = []

    def visit(name: str) -> list[str] | None:
        state[name] = 1
        path.append(name)
        for other in depends[name]:
            if state.get(other) == 1:
                return path[path.index(other):] + [other]
            if other not in state:
                found = visit(other)
                if found:
                    return found
        path.pop()
        state[name] = 2
        return None

    for name in depends:
        if name not in state:
            found = visit(name)
            if found:
                return found
    return None


def _check_folders(spec: BatchSpec, plans: list[RunPlan]) -> None:
    owners: dict[object, str] = {}
    for plan in plans:
        for path in (plan.folder, plan.settings_copy):
            other = owners.get(path)
            if other is not None:
                raise spec.error(f"runs '{other}' and '{plan.name}' write the same results folder or settings copy "
                                 f"{path}", element="<results_directory>",
                                 expected="a results folder of its own for every run (rename a run, a variant or "
                                          "give <results_directory>)")
            owners[path] = plan.name
    folders = sorted((p.folder, p.name) for p in plans)
    for (folder, name), (inner, other) in zip(folders, folders[1:]):
        if inner.is_relative_to(folder):
            raise spec.error(f"run '{other}' writes its results into {inner}, inside the results folder of run "
                             f"'{name}'", element="<results_directory>",
                             expected="results folders apart from each other")


def link(spec: BatchSpec, plans: list[RunPlan]) -> list[RunPlan]:
    """``plans`` with their dependencies and warm starts (module docstring)."""
    by_name = {p.name: p for p in plans}
    by_entry: dict[str, list[RunPlan]] = {}
    for plan in plans:
        by_entry.setdefault(plan.entry, []).append(plan)
    entries = {e.name: e for e in spec.entries}
    linked: list[RunPlan] = []
    for plan in plans:
        entry = entries[plan.entry]
        depends: list[str] = []
        for name in entry.depends_on:
            if name in by_entry:
                depends += [p.name for p in by_entry[name]]
            elif name in by_name:
                depends.append(name)
            else:
                raise spec.error(f"'{entry.name}' depends on '{name}', which is no run or sweep of the batch",
                                 line=entry.line, element="<depends_on>",
                                 expected="names of runs or sweeps: " + ", ".join(by_entry))
        warm = None
        if entry.warm_start_from is not None:
            parent, warm = _warm_start(spec, entry, by_name, by_entry)
            depends.append(parent)
        linked.append(attrs.evolve(plan, depends_on=tuple(dict.fromkeys(depends)), warm_start=warm))
    cycle = _cycle({p.name: p.depends_on for p in linked})
    if cycle:
        raise spec.error("a dependency cycle: " + " -> ".join(cycle), element="<depends_on>",
                         expected="runs that depend on earlier ones only")
    _check_folders(spec, linked)
    return linked


def order(plans: list[RunPlan]) -> list[RunPlan]:
    """``plans`` with every run after the runs it depends on (file order otherwise)."""
    done: set[str] = set()
    out: list[RunPlan] = []
    waiting = list(plans)
    while waiting:
        ready = [p for p in waiting if all(d in done for d in p.depends_on)]
        for plan in ready:
            done.add(plan.name)
            out.append(plan)
        waiting = [p for p in waiting if p.name not in done]
    return out
