"""Operations on scenes: reading and writing through the format registry, clipping, block
building, voxelization and fitting. Each facade validates its options and dispatches to the
plugin registered for the work (:mod:`geobrep.host`); the functions are exported by
:mod:`geobrep` (``geobrep.clip``, ``geobrep.read``, ...).
"""
