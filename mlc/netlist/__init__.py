"""Map stage: the gate netlist IR (:mod:`mlc.netlist.ir`) and technology mapping of an
AIG onto library gates and lever types (:mod:`mlc.netlist.mapper`)."""
