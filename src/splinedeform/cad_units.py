"""Length units of CAD files: what each format calls them and how long they are.

A surface read from a CAD file keeps the numbers of the file, in the file's length unit
(a key of :data:`UNITS`), and is written back in that unit: openNURBS ``UnitSystem``,
STEP ``LENGTH_UNIT``, IGES global-section unit flag. OpenCASCADE converts every file
to millimetres when it reads and from millimetres when it writes, so coordinates cross
it multiplied or divided by :func:`millimetres`.
"""

from __future__ import annotations

from .errors import InputError

#: unit -> (millimetres per unit, openNURBS UnitSystem name, OpenCASCADE unit name)
UNITS: dict[str, tuple[float, str, str]] = {
    "um": (1e-3, "Microns", "UM"),
    "mm": (1.0, "Millimeters", "MM"),
    "cm": (10.0, "Centimeters", "CM"),
    "m": (1000.0, "Meters", "M"),
    "km": (1e6, "Kilometers", "KM"),
    "in": (25.4, "Inches", "INCH"),
    "ft": (304.8, "Feet", "FT"),
}

#: STEP unit names (``SI_UNIT`` prefix + METRE, or a ``CONVERSION_BASED_UNIT`` name)
STEP_NAMES = {"micrometre": "um", "millimetre": "mm", "centimetre": "cm", "metre": "m",
              "kilometre": "km", "inch": "in", "foot": "ft", "feet": "ft"}

#: IGES global-section unit flags (parameter 14) that name one of :data:`UNITS`
IGES_FLAGS = {9: "um", 2: "mm", 10: "cm", 6: "m", 7: "km", 1: "in", 4: "ft"}


def check_units(units: str | None, what: str = "units") -> str | None:
    """``units`` if it is a key of :data:`UNITS` (or None: not known); else InputError."""
    if units is not None and units not in UNITS:
        raise InputError(f"{what} must be one of {', '.join(UNITS)}, got {units!r}")
    return units


def millimetres(units: str | None) -> float:
    """Millimetres per unit (1 for unknown units, written as millimetres)."""
    return 1.0 if units is None else UNITS[check_units(units)][0]


def units_from_rhino(name: str) -> str | None:
    """The unit of an openNURBS ``UnitSystem`` name (None: ``None`` or not one of ours)."""
    for units, (_, rhino, _) in UNITS.items():
        if rhino == name:
            return units
    return None


def rhino_name(units: str | None) -> str:
    """The openNURBS ``UnitSystem`` member of ``units`` (``None``: no unit)."""
    return "None" if units is None else UNITS[check_units(units)][1]


def occt_name(units: str | None) -> str:
    """OpenCASCADE's name of ``units`` for writing STEP / IGES (millimetres if unknown)."""
    return UNITS[check_units(units) or "mm"][2]
