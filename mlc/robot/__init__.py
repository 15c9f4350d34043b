"""Robot bodies driven by a compiled circuit (docs/robot.md): the file format
(:mod:`mlc.robot.spec`), the skeleton and its couplings (:mod:`mlc.robot.build`), shape
verification (:mod:`mlc.robot.verify`) and pictures (:mod:`mlc.robot.draw`)."""
