"""The two-generator BCH series served from a verified table shipped with the package.

A composition of two pieces with two factors or three symmetric ones (each piece's coefficients
sum to one, :class:`~nambu_bch.integrators.composition.Composition`) is one of four products:
``Z = log(e^A e^B)`` (``12``), its reverse ``log(e^B e^A)`` (``21``), ``S = log(e^{A/2} e^B e^{A/2})``
(``121``) and ``S' = log(e^{B/2} e^A e^{B/2})`` (``212``; the middle letter the smaller one, a
different expansion in the Lyndon basis over ``A < B``, not a renaming).  These series are
universal, so three of them are computed once and stored; the reverse follows from ``Z`` by
``log(e^B e^A) = -log(e^{-A} e^{-B})``, whose degree-``d`` part is ``(-1)^(d+1) Z_d``.

The table (``data/bch_series.bin``, 4.1 MB, written by ``tools/build_bch_table.py`` with the engine of
:mod:`nambu_bch.bch.formal`) holds to degree 22 (the symmetric series: their odd degrees to 21; their even
degrees vanish), per degree ``d``: the Lyndon words of length ``d`` in
lexicographic order as their standard factors (``P_w = [P_u, P_v]``, indices of shorter words), and
per series the numerators ``n_w`` over the least common denominator ``T_d`` of the degree, as
fixed-width little-endian integers.  A request to degree ``n`` rescales ``n_w`` to the denominators
``D_d = d! lcm(1..n) q^d`` of :func:`~nambu_bch.bch.formal.formal_bch` (``q`` the common denominator
of the coefficients) and builds the Python objects of the degrees asked only: the result is equal,
numerator by numerator, to the engine's.

Integrity.  The header (binary, :func:`record_format`: per degree the number of words, where its blocks lie,
the denominators and the SHA-256 of the degree's bytes) is trusted only when its own SHA-256 equals
:data:`TABLE_SHA256`, written into this module by the tool; a degree's bytes are decoded only when
their SHA-256 equals the header's.  A missing, damaged or replaced file is not used: the engine
computes the series, and one warning line says why.  The digests are hashlib's (OpenSSL) in a process that has
imported hashlib or when :data:`HASHLIB_BYTES` or more are checked at once (degrees 21-22), and CPython's built-in
SHA-256 otherwise: the same digest, without mapping libcrypto (megabytes) into a fresh process that reads a few
degrees of the table and nothing else.

Once per process.  The header and the bytes of each degree read so far are checked once and kept, as checked, in
memory (the verified image: the bytes of the degrees asked, at most the file's 4.1 MB, 1.2 MB to degree 20): a later
request decodes them from there (what was checked is what is decoded) and reads the file only for a degree it does not
hold yet.
:func:`nambu_bch.clear_caches` (through :func:`clear_decoded`) empties what was decoded from the image -- the
standard factors, numerators, trees and words -- and keeps the image, which is the shipped data as read, not the
result of a computation; :func:`clear_cache` forgets the image too.

Memory.  Only the degrees asked are read; the numerators stay machine integers (:mod:`array`) until a degree's
terms are asked for where they fit in 8 bytes (``log(e^A e^B)`` to degree 22: 63 bits at degrees 21-22; the symmetric
series need 9 bytes at degree 19 and 11 at degree 21 and are decoded into Python ints), and :class:`Served` builds
them on each access (the trees, shared by every request, are the only Python objects kept).

File format: ``b"NBCHTAB4"``, the header's length (4 bytes, little-endian), the header (:data:`PREAMBLE`, the
series' names in :data:`NAME_BYTES` each, one :func:`record_format` record per degree: fixed-size fields read
by :mod:`struct` in one call, where a JSON header cost more than the blocks of a request to degree 10), then
degree by degree the standard factors (int32: left indices, then right indices, into the flat list of the
Lyndon words of all degrees) and the three series' numerators, each block zlib-compressed unless it is small
(:func:`pack_block`: a block is raw exactly when its size is its decoded size, known from the number of words and
the bytes per numerator), the blocks beyond :data:`PLANE_BYTES` (those of degrees 21-22) by byte planes
(:func:`byte_planes`: 0.6 MB smaller); the blocks of degrees 1-20 are byte for byte those of the table to degree 20
(format 3), so that a request to degree 20 or less reads and decodes what it did.

References
----------
Casas & Murua, J. Math. Phys. 50 (2009) 033513 (the BCH series in the Lyndon basis, its
multidegree structure); Hofstätter, *Computing the BCH series* (arXiv:2102.06570), Sect. 2
(``log(e^A e^B)`` and the symmetric ``log(e^{A/2} e^B e^{A/2})``); Reutenauer, *Free Lie
Algebras* (1993), Thm. 5.1 (Lyndon basis, standard factorisation).
"""

from __future__ import annotations

import os
import stat
import struct
import sys
import _thread
import warnings
import zlib
from array import array
from collections.abc import Mapping
from fractions import Fraction

from .collector import no_full_collection

#: SHA-256 of the table's header (which holds the SHA-256 of each degree's bytes); written by tools/build_bch_table.py.
TABLE_SHA256 = "3061923e064f40f8dce6aa7d81ea401e8e1d37c6f0f7705b2982fa9ac462bdce"
#: The table file shipped with the package.
TABLE_PATH = os.path.join(os.path.dirname(__file__), "data", "bch_series.bin")
MAGIC = b"NBCHTAB4"
#: The header's fixed part: format version, letters, number of series, top degree, bytes of a denominator ``T_d``.
PREAMBLE = struct.Struct("<5H")
FORMAT_VERSION = 4
#: Bytes of a series' name in the header (ASCII, NUL-padded).
NAME_BYTES = 4
#: A block of at most this many bytes is stored as is: zlib shortens so few by tens of bytes, while each compressed
#: block costs a decompression call of its own (nineteen in a request to degree 10 when every block was compressed,
#: two now; the file is 294 bytes longer).
RAW_BYTES = 256
#: A compressed block of more than this many bytes (decoded) is stored by byte planes (:func:`byte_planes`), a smaller
#: one as its bytes are.  Interleaving the planes back is a strided copy of every byte, dear for a small block, so
#: only the blocks of degrees 21-22 are (0.6 MB of the file); every block above 16 kB would save 0.2 MB more at the
#: price of that copy in every request from degree 15 on, and the blocks of degrees 1-20 stay byte for byte those
#: of the table to degree 20 (``benchmarks/bch_table_format.py`` prints each encoding's size and decoding time).
PLANE_BYTES = 1 << 19


def pack_block(data: bytes, width: int = 1) -> bytes:
    """A block as the table stores it: ``data`` as is when it has at most :data:`RAW_BYTES` bytes or zlib does not
    shorten it, else zlib-compressed, by byte planes (:func:`byte_planes`, ``width`` bytes an integer) when it has
    more than :data:`PLANE_BYTES` bytes -- so a stored block is raw exactly when its size is ``len(data)`` (a
    compressed block is always shorter), which :func:`unpack_block` reads back without a flag."""
    if len(data) <= RAW_BYTES:
        return data
    compressed = zlib.compress(byte_planes(data, width) if len(data) > PLANE_BYTES else data, 9)
    return compressed if len(compressed) < len(data) else data


def byte_planes(data: bytes, width: int) -> bytes:
    """The ``width``-byte integers of ``data`` byte plane by byte plane: every integer's first byte, then every
    second byte, ...  The top bytes of numerators narrower than their width and the slowly varying top bytes of
    the standard factors' indices form long runs that zlib shortens far better than interleaved (degrees 21-22: the
    standard factors 2.3-2.5x, the numerators 3-13% smaller)."""
    return data if width == 1 else b"".join([data[k::width] for k in range(width)])


def unpack_block(block, size: int, width: int = 1):
    """The ``size`` bytes of a block stored by :func:`pack_block` with ``width`` (``block`` itself when it is stored
    raw, else decompressed and its byte planes interleaved again)."""
    if len(block) == size:
        return block
    planes = zlib.decompress(block)
    if width == 1 or size <= PLANE_BYTES:
        return planes
    count = size // width
    data = bytearray(size)
    for k in range(width):  # one strided copy a plane, in C
        data[k::width] = planes[k * count : (k + 1) * count]
    return data


def record_format(n_series: int, t_bytes: int) -> str:
    """The :mod:`struct` format of the header's record of one degree: the number of Lyndon words, the end of the
    degree's bytes, the standard factors' block (offset, size), per series its numerators' block (offset, size,
    bytes per numerator) and ``T_d`` (unsigned little-endian), and the SHA-256 of the degree's bytes (offsets
    count from the first block)."""
    return "<4I" + f"2IB{t_bytes}s" * n_series + "32s"

#: The series of the table: name -> ``(letters of the factors, their coefficients)``, letter 0 the smaller piece.
SERIES = {
    "12": ((0, 1), (Fraction(1), Fraction(1))),
    "121": ((0, 1, 0), (Fraction(1, 2), Fraction(1), Fraction(1, 2))),
    "212": ((1, 0, 1), (Fraction(1, 2), Fraction(1), Fraction(1, 2))),
}
#: :data:`SERIES` with the coefficients as ``(numerator, denominator)`` pairs (compared without Fractions)
_SERIES_PAIRS = {name: (letters, tuple((c.numerator, c.denominator) for c in coefficients))
                 for name, (letters, coefficients) in SERIES.items()}

try:  # CPython's own SHA-256 (the same digest) for a process that has not imported hashlib (module docstring)
    from _sha2 import sha256 as _builtin_sha256  # Python >= 3.12
except ImportError:
    try:
        from _sha256 import sha256 as _builtin_sha256  # Python <= 3.11
    except ImportError:
        _builtin_sha256 = None


def _sha256(data):
    """SHA-256 of ``data`` (:func:`_sha256_function`)."""
    return _sha256_function()(data)


#: Bytes checked at once from which hashlib is imported when it is not yet: importing it costs a fresh process about
#: 5 ms and 3.6 MB (libcrypto) and CPython's own SHA-256 several times hashlib's (``benchmarks/bch_table_format.py``
#: prints both), so it pays for the degrees 21-22 (2.9 MB) and not for a request to degree 20 or less (1.2 MB at most)
HASHLIB_BYTES = 1 << 21


def _sha256_function(size: int = 0):
    """The SHA-256 constructor: hashlib's (OpenSSL, several times faster) when hashlib is imported already or
    ``size`` bytes are to be checked, at least :data:`HASHLIB_BYTES`, else CPython's own -- importing hashlib maps
    libcrypto, megabytes of a fresh process that reads a few degrees of the table."""
    hashlib = sys.modules.get("hashlib")
    if hashlib is None and _builtin_sha256 is not None and size < HASHLIB_BYTES:
        return _builtin_sha256
    if hashlib is None:
        import hashlib
    return hashlib.sha256


#: Bytes read after the header with it (degrees 1-13 of the shipped table, 14 kB)
_FIRST_BLOCKS = 16384
#: array typecodes of the signed integer widths that convert in bulk
_TYPECODES = {array(code).itemsize: code for code in "bhiq"}
_INT32 = _TYPECODES[4]  # the standard factors' indices
#: [header dict] once read and verified; [None] when the table is unusable in this process.  The header holds the
#: verified image of the file: the header's fields and the bytes of each degree read so far, each checked against
#: its SHA-256 once and then kept (about a megabyte at the top degree), so that a later request, also after
#: :func:`clear_decoded`, decodes them from memory instead of reading and checking the file again.
_HEADER: list = []
_TREES: dict = {}  # generators -> [flat list of the trees, degrees done]
_WORDS: dict = {}  # generators -> [flat list of the Lyndon words as bytes of piece numbers, degrees done]
_FACTORS: list = []  # per degree decoded so far: the standard factors (left indices + right indices)
_NUMERATORS: dict = {}  # (series, degree) -> the stored numerators n_w (array of machine integers, or a list)
_LOCK = _thread.allocate_lock()  # _thread: the threading module is not imported for one lock


def clear_decoded() -> None:
    """Forget what was decoded from the table (standard factors, numerators, trees, words), keeping its verified
    image: the header and the degrees' bytes already checked against their SHA-256 (:data:`_HEADER`).

    This is the package's :func:`~nambu_bch.caches.clear_caches` entry: the image is the shipped data as this
    process read and checked it once (as it imports a module once), not the result of a computation; a request
    after this call decodes the degrees it asks for again.  A table found unusable is tried again."""
    with _LOCK:
        if _HEADER == [None]:
            _HEADER.clear()
        _TREES.clear()
        _WORDS.clear()
        _FACTORS.clear()
        _NUMERATORS.clear()


def clear_cache() -> None:
    """Forget the table entirely: its verified image and everything decoded (the next request reads the file and
    checks its SHA-256 again)."""
    with _LOCK:
        _HEADER.clear()
    clear_decoded()


def _unusable(reason: str) -> None:
    warnings.warn(f"nambu_bch: the BCH table {TABLE_PATH} is not used ({reason}); the series is computed instead",
                  RuntimeWarning, stacklevel=4)
    _HEADER[:] = [None]


def _read_table(offset: int, size: int, more=None) -> list:
    """``[the table's bytes offset .. offset + size]``, and with ``more`` (a function of those bytes giving a second
    ``(offset, size)`` or ``None``) the second span too, read from one opening of the file.

    The file is opened only if it is a regular file, never a link, FIFO or device (refused before it is opened, so
    opening cannot block), and read only if it is the very file checked (same device and inode after opening).
    Positional reads on the descriptor: no buffered file object is built for two reads."""
    before = os.lstat(TABLE_PATH)
    if not stat.S_ISREG(before.st_mode):
        raise OSError(f"{TABLE_PATH} is not a regular file")
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    fd = os.open(TABLE_PATH, flags)
    try:
        st = os.fstat(fd)
        if (st.st_dev, st.st_ino) != (before.st_dev, before.st_ino) or not stat.S_ISREG(st.st_mode):
            raise OSError(f"{TABLE_PATH} was replaced while it was opened")
        out = [_pread(fd, size, offset)]
        span = more(out[0]) if more is not None else None
        if span is not None:
            out.append(_pread(fd, span[1], span[0]))
        return out
    finally:
        os.close(fd)


def _pread(fd: int, size: int, offset: int) -> bytes:
    """Up to ``size`` bytes at ``offset`` (fewer only at the end of the file)."""
    if hasattr(os, "pread"):
        return os.pread(fd, size, offset)
    os.lseek(fd, offset, os.SEEK_SET)  # no pread (Windows): the descriptor is this call's own
    return os.read(fd, size)


def _header():
    """The verified header, or ``None`` (then a warning has been given once in this process).

    ``{"max_degree", "series" (name -> position), "degrees" (one :func:`record_format` tuple per degree),
    "base" (where the blocks start in the file), "first_blocks", "denominators" (name -> ``T_d`` of each degree as
    ints), "starts" (the index of each degree's first word among the Lyndon words of all degrees), "blocks" (per
    degree ``1, 2, ...`` whose bytes are checked against their SHA-256, its standard factors' block and
    ``{series: (numerators' block, bytes per numerator)}``, as stored: :func:`unpack_block`)}``."""
    if _HEADER:
        return _HEADER[0]
    lead = len(MAGIC) + 4

    def rest(start):  # the header and, with it, the first blocks (one opening for a request to a low degree)
        size = int.from_bytes(start[len(MAGIC) : lead], "little")
        return (lead, size + _FIRST_BLOCKS) if start[: len(MAGIC)] == MAGIC and size < 2**20 else None

    try:
        parts = _read_table(0, lead, rest)
    except OSError as exc:
        _unusable(f"cannot read it: {exc.strerror or exc}")
        return None
    size = int.from_bytes(parts[0][len(MAGIC) : lead], "little")
    raw = parts[1] if len(parts) > 1 else b""
    raw, first_blocks = raw[:size], raw[size:]
    if _sha256(raw).hexdigest() != TABLE_SHA256:
        _unusable("its SHA-256 does not match the package's")
        return None
    # the header is the tool's, byte for byte (its SHA-256 is pinned above): its layout needs no further checks
    version, _, n_series, top, t_bytes = PREAMBLE.unpack_from(raw)
    names = raw[PREAMBLE.size : PREAMBLE.size + NAME_BYTES * n_series]
    record = record_format(n_series, t_bytes)  # struct keeps the compiled formats it has seen
    at = PREAMBLE.size + len(names)
    degrees = list(struct.iter_unpack(record, raw[at : at + struct.calcsize(record) * top]))
    # each name -> where its numerators' block lies in a record
    series = {names[i : i + NAME_BYTES].rstrip(b"\0").decode("ascii"): 4 + 4 * (i // NAME_BYTES)
              for i in range(0, len(names), NAME_BYTES)}
    starts = [0]
    for fields in degrees:
        starts.append(starts[-1] + fields[0])
    header = {
        "max_degree": top,
        "series": series,
        "degrees": degrees,
        "base": len(MAGIC) + 4 + size,
        "first_blocks": first_blocks,  # unverified bytes: each degree's SHA-256 is checked before it is kept
        # read once here rather than in every request: T_d and where each degree's words start
        "denominators": {name: [0] + [int.from_bytes(fields[k + 3], "little") for fields in degrees]
                         for name, k in series.items()},
        "starts": starts,
        "blocks": [],
    }
    _HEADER[:] = [header]
    return header


def _numerators_block(header, d: int, series: str) -> tuple:
    """``(offset, size, bytes per numerator, T_d)`` of the numerators of ``series`` in degree ``d``."""
    record, at = header["degrees"][d - 1], header["series"][series]
    return record[at], record[at + 1], record[at + 2], header["denominators"][series][d]


def _decode(data: bytes, width: int):
    """The ``width``-byte little-endian two's-complement integers of ``data``: an :class:`array.array` when a
    machine type has that width (8 bytes a number, Python ints only when a term is asked for), else a list."""
    code = _TYPECODES.get(width)
    if code is not None:  # in bulk, without numpy (not imported on this path)
        values = array(code)
        values.frombytes(data)
        if sys.byteorder == "big":
            values.byteswap()
        return values
    from_bytes = int.from_bytes
    return [from_bytes(data[i : i + width], "little", signed=True) for i in range(0, len(data), width)]


def _verify(header, n: int) -> bool:
    """Extend the verified image (``header["blocks"]``) to degree ``n``: the degrees' bytes not checked yet are
    read in one piece (or taken from the bytes read with the header) and each degree's bytes are kept only if
    their SHA-256 equals the header's.  The caller holds :data:`_LOCK`."""
    blocks, degrees = header["blocks"], header["degrees"]
    first = len(blocks) + 1
    if first > n:
        return True
    start = degrees[first - 2][1] if first > 1 else 0
    stop = degrees[n - 1][1]
    if stop <= len(header["first_blocks"]):  # read with the header
        data, shift = header["first_blocks"], 0
    else:
        shift = start  # the bytes read start there (the records' offsets count from the first block)
        try:
            data = _read_table(header["base"] + start, stop - start)[0]
        except OSError as exc:
            _unusable(f"cannot read it: {exc.strerror or exc}")
            return False
        if len(data) != stop - start:
            _unusable("it is shorter than its header says")
            return False
    view = memoryview(data)
    sha256 = _sha256_function(stop - start)
    series = header["series"]
    low = start
    for d in range(first, n + 1):
        record = degrees[d - 1]
        end = record[1]
        if sha256(view[low - shift : end - shift]).digest() != record[-1]:
            _unusable(f"the bytes of degree {d} do not match their SHA-256")
            return False
        # views of the bytes read, cut once here: what was checked is what is decoded, now and after clear_decoded
        offset = record[2] - shift
        blocks.append((view[offset : offset + record[3]],
                       {name: (view[record[at] - shift : record[at] - shift + record[at + 1]], record[at + 2])
                        for name, at in series.items()}))
        low = end
    return True


def _load(header, series: str, n: int) -> bool:
    """Decode the standard factors and the numerators of ``series`` for the degrees ``<= n`` not decoded yet, from
    the verified image (:func:`_verify` extends it first when a degree is missing).  The caller holds
    :data:`_LOCK`.

    Both are decoded degree by degree from degree 1 up, so what is decoded is always degrees ``1..m``: degree
    ``n`` present means every lower one is."""
    if len(_FACTORS) >= n and (series, n) in _NUMERATORS:
        return True
    image = header["blocks"]
    if len(image) < n and not _verify(header, n):
        return False
    degrees = header["degrees"]
    for d in range(len(_FACTORS), n):
        factors = array(_INT32)
        if d:  # degree 1 has no standard factors; degree d + 1 two int32 indices a word
            factors.frombytes(unpack_block(image[d][0], 8 * degrees[d][0], 4))
            if sys.byteorder == "big":  # the table is little-endian
                factors.byteswap()
        _FACTORS.append(factors)
    for d in range(1, n + 1):
        if (series, d) not in _NUMERATORS:
            block, width = image[d - 1][1][series]
            _NUMERATORS[series, d] = (_decode(unpack_block(block, width * degrees[d - 1][0], width), width)
                                      if width else [])
    return True


def _trees(generators: tuple, factors: list, n: int) -> list:
    """The standard bracketings of the Lyndon words of degrees ``1..n`` as one flat list (degree by degree,
    lexicographic within a degree), leaves named by ``generators``, from the standard factors of each degree.

    Kept per generators and extended degree by degree; the caller holds :data:`_LOCK`."""
    state = _TREES.get(generators)
    if state is None:
        state = _TREES[generators] = [[generators[0], generators[1]], 1]
    trees = state[0]
    if state[1] < n:
        with no_full_collection():  # acyclic tuples: nothing for the collector to find
            for d in range(state[1] + 1, n + 1):
                pairs = factors[d - 1]
                m = len(pairs) // 2
                trees.extend([(trees[left], trees[right]) for left, right in zip(pairs[:m], pairs[m:])])
                state[1] = d
    return trees


def _words(generators: tuple, factors: list, n: int) -> list:
    """The Lyndon words of degrees ``1..n`` as one flat list in the order of :func:`_trees`, each word the
    ``bytes`` of its piece numbers (all below 256), from the standard factors: ``w = u v`` is one concatenation
    of two shorter words, so no tree is walked.

    Kept per generators and extended degree by degree; the caller holds :data:`_LOCK`."""
    state = _WORDS.get(generators)
    if state is None:
        state = _WORDS[generators] = [[bytes(generators[:1]), bytes(generators[1:])], 1]
    words = state[0]
    if state[1] < n:
        with no_full_collection():  # bytes objects only: nothing for the collector to find
            for d in range(state[1] + 1, n + 1):
                pairs = factors[d - 1]
                m = len(pairs) // 2
                words.extend([words[left] + words[right] for left, right in zip(pairs[:m], pairs[m:])])
                state[1] = d
    return words


def _request(letters, values, q: int):
    """``(series, reversed)`` when the product is a stored series or the reverse of ``log(e^A e^B)``, else ``None``."""
    letters = tuple(letters)
    for name, (stored, pairs) in _SERIES_PAIRS.items():
        if letters == stored and all(v * b == a * q for v, (a, b) in zip(values, pairs)):
            return name, False
    stored, pairs = _SERIES_PAIRS["12"]
    if letters[::-1] == stored and all(v * b == a * q for v, (a, b) in zip(values[::-1], pairs)):
        return "12", True
    return None


def max_degree() -> int:
    """The highest degree the table holds (0 when it is unusable in this process)."""
    header = _header()
    return 0 if header is None else header["max_degree"]


def serve(letters, values, q: int, generators: tuple, n: int, denominators):
    """``{degree: (D_d, ((numerator, tree), ...))}`` of the product from the table, or ``None`` if not served.

    ``letters`` (``0`` for the smaller generator) and ``values`` (integers, coefficients
    ``values / q``) describe the factors, ``denominators[d] = D_d``; the numerators are
    ``D_d`` times the coefficients, the same Python ints the engine returns, non-zero ones only,
    Lyndon words of each degree in lexicographic order.  The mapping (:class:`Served`) builds a degree's
    pairs when it is asked for; the stored numerators stay machine integers until then.
    """
    if len(generators) != 2 or n < 1:
        return None
    request = _request(letters, values, q)
    if request is None:
        return None
    header = _header()
    if header is None or n > header["max_degree"]:
        return None
    series, flip = request
    with _LOCK:  # the decoded degrees are appended in order: one request at a time extends them
        if not _load(header, series, n):
            return None
        factors = _FACTORS[:n]
        stored = [_NUMERATORS[series, d] for d in range(1, n + 1)]
    common, starts = header["denominators"][series], header["starts"]
    even = -1 if flip else 1  # the reversed product: the even degrees change sign
    parts = {}
    for d in range(1, n + 1):
        numerators = stored[d - 1]
        if numerators:
            # D_d / T_d is an integer: T_d is the least common denominator of the degree, and D_d times every
            # coefficient is an integer (the engines' denominators, nambu_bch.bch.formal)
            factor, rest = divmod(denominators[d], common[d])
            if rest:
                raise ArithmeticError(f"internal error: the BCH table's degree-{d} denominator does not divide "
                                      f"{denominators[d]}")
            parts[d] = (denominators[d], factor if d % 2 else even * factor, numerators, starts[d - 1])
    return Served(tuple(generators), factors, parts)


class Served(Mapping):
    """``{degree: (D_d, ((numerator, tree), ...))}`` read from the table, each degree built when it is asked for.

    Holds per degree ``D_d``, the factor ``D_d / T_d`` (negated in the even degrees of the reversed product
    ``log(e^B e^A)``), the stored numerators ``n_w`` and the index of the degree's first word among the trees; a
    degree's pairs ``(n_w D_d / T_d, P_w)`` are built on each access (nothing is kept but the trees,
    shared by every request).  Pickles as the plain dict it stands for.
    """

    __slots__ = ("_generators", "_factors", "_parts")

    def __init__(self, generators: tuple, factors: list, parts: dict):
        self._generators, self._factors, self._parts = generators, factors, parts

    def __getitem__(self, degree):
        den, factor, stored, start = self._parts[degree]
        with _LOCK:
            trees = _trees(self._generators, self._factors, len(self._factors))
        return den, tuple([(v * factor, trees[k]) for v, k in zip(stored, range(start, start + len(stored))) if v])

    def words(self, degree):
        """``(D_d, iterator of (numerator, word))`` of ``degree``: the pairs of ``self[degree]`` with each tree
        replaced by its Lyndon word (a tuple of piece numbers, the tree's leaves), built one by one from the
        standard factors without the trees."""
        den, factor, stored, start = self._parts[degree]
        generators = self._generators
        if max(generators) > 255:  # a word is kept as bytes of piece numbers: beyond a byte, walk the trees
            from .lyndon import tree_leaves

            den, items = self[degree]
            return den, ((v, tree_leaves(t)) for v, t in items)
        with _LOCK:
            words = _words(generators, self._factors, len(self._factors))
        return den, ((v * factor, tuple(words[k])) for v, k in zip(stored, range(start, start + len(stored))) if v)

    def __iter__(self):
        return iter(self._parts)

    def __len__(self):
        return len(self._parts)

    def __contains__(self, degree):
        return degree in self._parts

    def count(self, degree) -> int:
        """The number of non-zero terms of ``degree`` (0 when it has none), without building them."""
        part = self._parts.get(degree)
        return 0 if part is None else len(part[2]) - part[2].count(0)

    def __reduce__(self):
        return dict, (list(self.items()),)
