"""Post-processing: reads results (a folder or frames), never the live solver (docs/architecture.md).

* :mod:`.results`: the results folder, written increment by increment and read back (:class:`Results`);
* :mod:`.vtk`: VTK export for ParaView; :mod:`.render`: off-screen PNG of the deformed shape;
* :mod:`.plotstyle`: the one matplotlib style of every femast figure.
"""
