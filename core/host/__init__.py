"""The plugin host: hook specifications, the registries plugins fill, and the plugin loader.

Core finds formats, clippers, fitters, builders and voxelizers here (``registries()``); plugin
authors import the same types from :mod:`geobrep.plugins`.
"""
