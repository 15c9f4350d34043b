"""logic: specifications -> minimum-AND And-Inverter Graphs, proven equivalent.

Public API (see docs/synthesis.md):

* :class:`mlc.logic.aig.AIG` -- the IR (literals ``2*node + complement``);
* :func:`mlc.logic.lower.from_spec` -- a first AIG for a TableSpec or NetworkSpec;
* :func:`mlc.logic.synth.synthesize` -- optimised AIG at effort 0..3, equivalence proven;
* :func:`mlc.logic.equiv.check_equivalent` -- exhaustive / BDD equivalence, don't cares respected;
* :func:`mlc.logic.aigio.write_blif`, :func:`mlc.logic.aigio.write_aiger` -- writers.
"""
