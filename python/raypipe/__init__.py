"""raypipe's bit-accurate ray-tracing datapath models (the RTI, slab and per-op units) for
Python and cocotb testbenches.

    >>> import raypipe, numpy as np
    >>> u = raypipe.Unit("rti", "f32")
    >>> u.eval([u.encode(x) for x in (0.25, 0.25, -1, 0, 0, 1, 0, 10, 0, 0, 0, 1, 0, 0, 0, 1, 0)])
    {'valid': 1, 'hit': 1, 't': 1065353216, 'u': 1048576000, 'v': 1048576000}

Rows are the vector files' rows: encodings in uint64 (flags 0 or 1). `Unit.eval_batch` takes a
(n, inputs) uint64 array and runs the SIMD kernels with the GIL released.

`Cover` records the functional coverage of the rows a testbench drives (docs/coverage.md).
"""

from ._raypipe import Cover, Unit, parse_format, read_set, version

__all__ = ["Cover", "Unit", "parse_format", "read_set", "version"]
