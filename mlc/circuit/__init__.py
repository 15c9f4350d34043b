"""Place-and-route stage: a gate netlist becomes one circuit scene (gates, connector
chains, branches, half units, input muscles and output probes)."""
