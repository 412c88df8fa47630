"""File formats and library bridges, registered as plugins through ``geobrep_register_formats``."""
