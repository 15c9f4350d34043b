"""Front end: parsers (one module per input format) producing the plain data of :mod:`mlc.spec`."""
