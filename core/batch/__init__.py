"""Work over many files: format conversion and pipeline files, run here, in processes or on a
Dask cluster, with one report per input.
"""
