"""Running the ``frequency`` step of model scripts (Abaqus *FREQUENCY after a *STATIC step).

``model.frequency_step("modes", n_modes=10)`` appends a step that changes nothing: the analysis
computes the lowest ``n_modes`` modes of the state reached so far (the initial state if it is the
first step, else the end of the previous step: prestress, loads and joint/latch states included),
keeps them in ``analysis.modes[step name]`` and writes ``<results>/modes/<step name>.npz`` and
``.csv`` (:class:`femast.modal.Modes`), with ``vtk=True`` also the animated series
``<results>/modes/<step name>_vtk/mode_NN/series.pvd``.  The loads of the previous step stay
applied to the steps after it.
"""

from __future__ import annotations

from pathlib import Path

from ..model.frequency import FrequencyStep, add_frequency_step, is_frequency_step  # noqa: F401  (the definition)


def run_frequency_step(analysis, step):
    """Compute and store the modes of ``analysis``' current state for ``step`` (called by the
    analysis' step loop); returns the :class:`~femast.modal.Modes`."""
    from .modes import modal_analysis
    from .output import export_modes_vtk

    label = f"frequency step '{step.name}'"
    modes = modal_analysis(analysis, step.n_modes, shift_hz=step.shift_hz, label=label)
    if not hasattr(analysis, "modes") or analysis.modes is None:
        analysis.modes = {}
    analysis.modes[step.name] = modes
    if analysis.out is not None:
        folder = Path(analysis.out) / "modes"
        modes.write(folder, step.name)
        if step.vtk:
            export_modes_vtk(modes, folder / f"{step.name}_vtk")
    analysis.summary.steps.append(
        {"name": step.name, "kind": "frequency", "frequencies_hz": [float(f) for f in modes.frequencies]}
    )
    if analysis.progress:
        from tqdm.auto import tqdm

        tqdm.write(modes.table())
    return modes
