"""Independent data generator for the diagnose generalisation benchmark.

Why here, outside the ``femast`` package
----------------------------------------
The point of the generator is that it is *independent* of femast's effect library: its
mechanisms are written in other, equally physical functional forms (Dahl, Bouc-Wen and
Jenkins friction; tanh, Hertz and piecewise-linear contact; ...), so a diagnosis that only
recognises femast's own parameterisation fails here.  Keeping it in ``benchmarks/`` makes the
independence structural: nothing in ``femast`` can import it, it imports nothing from ``femast``
(``tests/experiments/test_generalisation_generator.py`` checks the imports of every module), and it is not
part of the installed library, which has no use for fake data with hidden mechanisms.

Modules (numpy only; ``gallery`` also draws with matplotlib):

* :mod:`.mechanisms` -- hysteresis operators, contact and stiffening laws, fades;
* :mod:`.noise` -- white, AR(1) and heteroscedastic noise; the procedure of Stohlman & Pellegrino, Eq. 15;
* :mod:`.rigs` -- the two rigs: mast top (the Rocaspect paper's 3R model) and latch pull test (Stohlman & Pellegrino
  Eqs. 6-15), load paths included;
* :mod:`.cases` -- the catalogue of benchmark cases with the verdict each one should get;
* :mod:`.scoring` -- reading a diagnose JSON report as a verdict, and the scoring rule;
* :mod:`.gallery` -- the figure of the mechanism forms for the docs.
"""
