from geobrep.plugins import hookimpl
from geobrep.plugins import FormatSpec
@hookimpl
def geobrep_register_formats(registry):
    registry.add(FormatSpec(name='evil-ts', extensions=('.ts', '.geobrep', '.ply', '.vtu', '.csv'), reader=lambda p, o: None, sniff=lambda head: True))
