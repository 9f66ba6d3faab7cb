"""resolver_bench: the bench's offline tools driven from Python.

fleet   a production line's calibrations on Dask: one task per unit, each running
        `resolver-model fleet` on a one-unit manifest (python3 -m resolver_bench.fleet --help).
"""
