"""openNURBS binary archive records of NURBS curves, NURBS surfaces and Breps, written byte
by byte as ``ON_BinaryArchive`` writes them (version 6 archives, ``Archive3dmVersion`` 60).

rhino3dm (8.x) cannot build a Brep's topology, but it reads any object from its archive
form: ``rhino3dm.CommonObject.Decode({"version": 10000, "archive3dm": 60, "opennurbs": v,
"data": base64})`` (the inverse of ``Encode()``). This module writes that form for an
``ON_Brep`` (``opennurbs_brep_io.cpp``: ``ON_Brep::Write`` and the ``Write`` of its
vertices, edges, trims, loops and faces), its ``ON_NurbsCurve`` and ``ON_NurbsSurface``
pieces (``opennurbs_nurbscurve.cpp``, ``opennurbs_nurbssurface.cpp``), in the chunks of
``opennurbs_archive.cpp``:

* a chunk is its type code (``uint32``), its length (``int64``, little-endian, as every
  number here) and its content; a type code with the bit ``TCODE_CRC = 0x8000`` ends its
  content with the CRC-32 (zlib's) of the bytes written directly into it (not those of
  the chunks nested in it, nor their headers);
* an object (``WriteObject``) is a ``TCODE_OPENNURBS_CLASS`` chunk holding a
  ``TCODE_OPENNURBS_CLASS_UUID`` chunk (the class id), a ``TCODE_OPENNURBS_CLASS_DATA``
  chunk (the class's ``Write``) and an empty ``TCODE_OPENNURBS_CLASS_END`` chunk;
* a chunk version ``major.minor`` is the byte ``16 major + minor``.

Knot vectors are openNURBS' (``N + n - 1`` knots: the full vector without its first and
last knot) and a rational control point is homogeneous, ``(w x, w y, w z, w)``.
"""

from __future__ import annotations

import base64
import struct
import uuid
import zlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

TCODE_CRC = 0x8000
TCODE_ANONYMOUS_CHUNK = 0x40008000
TCODE_OPENNURBS_CLASS = 0x00027FFA
TCODE_OPENNURBS_CLASS_UUID = 0x0002FFFB
TCODE_OPENNURBS_CLASS_DATA = 0x0002FFFC
TCODE_OPENNURBS_CLASS_END = 0x80027FFF
#: class ids (``ON_OBJECT_IMPLEMENT``) of the objects written here
CLASS_ID = {"brep": "60B5DBC5-E660-11d3-BFE4-0010830122F0",
            "curve": "4ED7D4DD-E947-11d3-BFE5-0010830122F0",
            "surface": "4ED7D4DE-E947-11d3-BFE5-0010830122F0"}
#: the archive version written (``Archive3dmVersion``): the chunk versions chosen here
#: (``ON_NurbsCurve`` 1.1, ``ON_BrepFaceArray`` 1.1) are those of a version 6 archive
ARCHIVE_3DM = 60
#: the empty bounding box openNURBS writes where a box is "reserved": min (1, 0, 0), max (-1, 0, 0)
EMPTY_BOX = (1.0, 0.0, 0.0, -1.0, 0.0, 0.0)


class Archive:
    """Bytes of an openNURBS archive being written, with its open chunks (module docstring)."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.stack: list[dict[str, Any]] = []

    def raw(self, data: bytes) -> None:
        """Write ``data`` into the innermost open chunk (its CRC counts them)."""
        if self.stack:
            top = self.stack[-1]
            top["body"].append(data)
            top["crc"] = zlib.crc32(data, top["crc"])
        else:
            self.parts.append(data)

    def ints(self, *values: int) -> None:
        self.raw(struct.pack(f"<{len(values)}i", *values))

    def doubles(self, values: Any) -> None:
        v = np.ascontiguousarray(values, dtype="<f8").ravel()
        self.raw(v.tobytes())

    def byte(self, value: int) -> None:
        self.raw(bytes([value]))

    def int_array(self, values: list[int]) -> None:
        """``WriteArray(ON_SimpleArray<int>)``: the count, then the values."""
        self.ints(len(values), *values)

    def uuid(self, text: str) -> None:
        """``WriteUuid``: ``Data1`` (uint32), ``Data2``, ``Data3`` (uint16), ``Data4[8]``."""
        u = uuid.UUID(text)
        d1, d2, d3 = u.fields[:3]
        self.raw(struct.pack("<IHH", d1, d2, d3) + u.bytes[8:])

    def begin(self, typecode: int) -> None:
        self.stack.append({"code": typecode, "body": [], "crc": 0})

    def end(self) -> None:
        """Close the innermost chunk: its header, content and CRC go into its parent."""
        top = self.stack.pop()
        body = b"".join(top["body"])
        if top["code"] & 0x80000000:                  # a short chunk: no content
            data = struct.pack("<Iq", top["code"], 0)
        else:
            if top["code"] & TCODE_CRC:
                body += struct.pack("<I", top["crc"])
            data = struct.pack("<Iq", top["code"], len(body)) + body
        if self.stack:                                 # not counted in the parent's CRC
            self.stack[-1]["body"].append(data)
        else:
            self.parts.append(data)

    def version(self, major: int, minor: int) -> None:
        """``Write3dmChunkVersion``: one byte ``16 major + minor``."""
        self.byte(16 * major + minor)

    def object(self, kind: str, write: Any, *args: Any) -> None:
        """``WriteObject``: the class chunk of ``CLASS_ID[kind]``, ``write(self, *args)`` in it."""
        self.begin(TCODE_OPENNURBS_CLASS)
        self.begin(TCODE_OPENNURBS_CLASS_UUID)
        self.uuid(CLASS_ID[kind])
        self.end()
        self.begin(TCODE_OPENNURBS_CLASS_DATA)
        write(self, *args)
        self.end()
        self.begin(TCODE_OPENNURBS_CLASS_END)
        self.end()
        self.end()

    def data(self) -> bytes:
        if self.stack:
            raise RuntimeError("an archive chunk is still open")
        return b"".join(self.parts)


@dataclass(frozen=True)
class Nurbs:
    """A NURBS curve (``points`` ``(N, d)``) or surface (``(N_u, N_v, 3)``): degrees, full
    clamped-or-not knot vectors (``N + n + 1`` each), points and weights (None: all 1)."""

    degrees: tuple[int, ...]
    knots: tuple[NDArray[np.float64], ...]
    points: NDArray[np.float64]
    weights: NDArray[np.float64] | None = None

    def homogeneous(self) -> NDArray[np.float64]:
        """Control points as openNURBS stores them: ``(w x, .., w)`` if rational, else ``x``."""
        P = np.asarray(self.points, dtype=float)
        if self.weights is None:
            return P
        w = np.asarray(self.weights, dtype=float)[..., None]
        return np.concatenate([P * w, w], axis=-1)


def write_curve(archive: Archive, curve: Nurbs) -> None:
    """``ON_NurbsCurve::Write`` (chunk version 1.1 for version 6 archives)."""
    archive.version(1, 1)
    (n,), (knots,) = curve.degrees, curve.knots
    cv = curve.homogeneous()
    archive.ints(cv.shape[1] - (curve.weights is not None), int(curve.weights is not None),
                 n + 1, cv.shape[0], 0, 0)
    archive.doubles(EMPTY_BOX)
    inner = np.asarray(knots, dtype=float)[1:-1]
    archive.ints(inner.size)
    archive.doubles(inner)
    archive.ints(cv.shape[0])
    archive.doubles(cv)
    archive.byte(0)                                   # SubDFriendlyTag: false


def write_surface(archive: Archive, surface: Nurbs) -> None:
    """``ON_NurbsSurface::Write`` (chunk version 1.0); points row by row in ``u``."""
    archive.version(1, 0)
    cv = surface.homogeneous()
    (nu, nv), (cu, cv_) = surface.degrees, cv.shape[:2]
    archive.ints(3, int(surface.weights is not None), nu + 1, nv + 1, cu, cv_, 0, 0)
    archive.doubles(EMPTY_BOX)
    for knots in surface.knots:
        inner = np.asarray(knots, dtype=float)[1:-1]
        archive.ints(inner.size)
        archive.doubles(inner)
    archive.ints(cu * cv_)
    archive.doubles(cv)


@dataclass
class BrepRecord:
    """The arrays of an ``ON_Brep`` (``m_C2``, ``m_C3``, ``m_S``, ``m_V``, ``m_E``,
    ``m_T``, ``m_L``, ``m_F``), each element a dict of its fields as openNURBS names
    them (without the ``m_``): vertex ``point``, ``ei``; edge ``c3i``, ``vi`` (2),
    ``ti``, ``domain``; trim ``c2i``, ``domain``, ``ei`` (-1: singular), ``vi`` (2),
    ``rev3d``, ``type``, ``iso``, ``li``; loop ``ti``, ``type``, ``fi``; face ``li``,
    ``si``, ``rev``. Vertices and edges may give a ``tolerance`` (default 0, openNURBS'
    "exact"); trims' are 0."""

    curves_2d: list[Nurbs] = field(default_factory=list)
    curves_3d: list[Nurbs] = field(default_factory=list)
    surfaces: list[Nurbs] = field(default_factory=list)
    vertices: list[dict[str, Any]] = field(default_factory=list)
    edges: list[dict[str, Any]] = field(default_factory=list)
    trims: list[dict[str, Any]] = field(default_factory=list)
    loops: list[dict[str, Any]] = field(default_factory=list)
    faces: list[dict[str, Any]] = field(default_factory=list)


def _array(archive: Archive, items: list[Any], write: Any, minor: int = 0) -> None:
    archive.begin(TCODE_ANONYMOUS_CHUNK)
    archive.version(1, minor)
    archive.ints(len(items))
    for item in items:
        write(item)
    if minor:                                          # faces: their uuids (nil)
        archive.raw(bytes(16 * len(items)))
    archive.end()


def write_brep(archive: Archive, brep: BrepRecord) -> None:
    """``ON_Brep::Write`` (chunk version 3.3): the eight arrays, an empty bounding box
    (recomputed on reading), no render or analysis meshes, ``m_is_solid = 0`` (not
    known: computed when asked) and no region topology."""
    a = archive
    a.version(3, 3)
    for items, kind in ((brep.curves_2d, "curve"), (brep.curves_3d, "curve"),
                        (brep.surfaces, "surface")):
        def one(item: Nurbs, kind: str = kind) -> None:
            a.ints(1)
            a.object(kind, write_curve if kind == "curve" else write_surface, item)
        _array(a, items, one)

    def vertex(v: dict[str, Any]) -> None:
        a.ints(v["index"])
        a.doubles(v["point"])
        a.int_array(v["ei"])
        a.doubles([v.get("tolerance", 0.0)])

    def edge(e: dict[str, Any]) -> None:
        a.ints(e["index"], e["c3i"], 0)
        a.doubles(e["domain"])
        a.ints(*e["vi"])
        a.int_array(e["ti"])
        a.doubles([e.get("tolerance", 0.0), *e["domain"]])

    def trim(t: dict[str, Any]) -> None:
        a.ints(t["index"], t["c2i"])
        a.doubles(t["domain"])
        a.ints(t["ei"], *t["vi"], int(t["rev3d"]), t["type"], t["iso"], t["li"])
        a.doubles([0.0, 0.0, *t["domain"]])
        a.raw(bytes(32))                              # proxy not reversed; reserved
        a.doubles([0.0, 0.0])                         # legacy 2-D and 3-D tolerances

    def loop(lp: dict[str, Any]) -> None:
        a.ints(lp["index"])
        a.int_array(lp["ti"])
        a.ints(lp["type"], lp["fi"])

    def face(f: dict[str, Any]) -> None:
        a.ints(f["index"])
        a.int_array(f["li"])
        a.ints(f["si"], int(f["rev"]), 0)

    for items, write in ((brep.vertices, vertex), (brep.edges, edge), (brep.trims, trim),
                         (brep.loops, loop)):
        _array(a, items, write)
    _array(a, brep.faces, face, minor=1)
    a.doubles(EMPTY_BOX)
    for _ in range(2):                                # render, analysis meshes: none
        a.begin(TCODE_ANONYMOUS_CHUNK)
        a.raw(bytes(len(brep.faces)))
        a.end()
    a.ints(0)                                         # m_is_solid: not known
    a.begin(TCODE_ANONYMOUS_CHUNK)                    # chunk version 3.3: region topology
    a.ints(1, 1)
    a.byte(0)
    a.end()


def brep_bytes(brep: BrepRecord) -> bytes:
    """The archive form of ``brep`` as one object (what ``Encode()`` holds)."""
    archive = Archive()
    for kind, items in (("vertices", brep.vertices), ("edges", brep.edges),
                        ("trims", brep.trims), ("loops", brep.loops), ("faces", brep.faces)):
        for k, item in enumerate(items):
            item.setdefault("index", k)
    archive.object("brep", write_brep, brep)
    return archive.data()


def decode(data: bytes, r3: Any) -> Any:
    """The rhino3dm object of an archive form (``CommonObject.Decode``, under the
    installed rhino3dm's own ``version`` and ``opennurbs`` numbers, as its ``Encode()``
    gives them, and :data:`ARCHIVE_3DM`); None if it fails."""
    header = r3.Point(r3.Point3d(0.0, 0.0, 0.0)).Encode()
    return r3.CommonObject.Decode({"version": header["version"], "archive3dm": ARCHIVE_3DM,
                                   "opennurbs": header["opennurbs"],
                                   "data": base64.b64encode(data).decode("ascii")})
