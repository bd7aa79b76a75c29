"""The parts of :class:`geometry.sweep.Sweeper`, one module each (mixins of the sweeper).

* :mod:`.shadow` -- the exact stationary shadows it samples, and the lines of their edges;
* :mod:`.blind` -- the exact point test (is a placement blind to the target?);
* :mod:`.events` -- the collinearity events and the samples next to the live ones;
* :mod:`.wedges` -- the event samples that the known shadows make needless;
* :mod:`.births` -- the birth checks (shadows born and gone between samples);
* :mod:`.trace` -- the tracing of the moving shadow edges between samples;
* :mod:`.cover` -- what the traces must cover, and the refinements where they do not;
* :mod:`.lines` -- lines and directions, row by row.

:mod:`geometry.sweep` holds the sweeper itself (its state, the order of the phases) and
:func:`~geometry.sweep.swept_shadows`.
"""
