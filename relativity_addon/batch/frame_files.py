"""Frame output files: their names, the partial name a frame is written to before it is complete,
and whether a file on disk is a complete image. Pure Python (no bpy, no imaging library), so the
coordinator of a distributed render (``farm.py``) can check outputs without starting Blender.

Completeness:

- PNG: the signature, every chunk's CRC, IHDR first and IEND last with nothing after it, and the
  image data decompresses to exactly the size IHDR announces (a truncated, cut or byte-flipped
  file fails).
- OpenEXR (single-part scan-line files, what Blender writes for ``.exr``): the header, the line
  offset table and every chunk it points to lie within the file, and the last chunk ends at the end
  of the file. EXR has no checksums, so a flipped byte inside pixel data is not detected; a cut or
  partly written file is.
"""

import math
import os
import re
import struct
import tempfile
import zlib

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PNG_CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}  # colour type -> samples per pixel
EXR_MAGIC = 20000630
# Scan lines per chunk for each EXR compression (OpenEXR's numbering).
EXR_LINES_PER_CHUNK = {0: 1, 1: 1, 2: 1, 3: 16, 4: 32, 5: 16, 6: 32, 7: 32, 8: 32, 9: 256}


def frame_output_path(out_path: str, frame: int, several: bool) -> str:
    """The file for ``frame``: a run of '#' becomes the zero-padded frame number; otherwise,
    when several frames are rendered, ``_NNNN`` is inserted before the extension."""
    directory, name = os.path.split(out_path)
    run = re.search(r"#+", name)
    if run:
        width = len(run.group(0))
        number = f"-{abs(frame):0{max(width - 1, 1)}d}" if frame < 0 else f"{frame:0{width}d}"
        return os.path.join(directory, name[: run.start()] + number + name[run.end() :])
    if not several:
        return out_path
    stem, extension = os.path.splitext(name)
    number = f"-{abs(frame):03d}" if frame < 0 else f"{frame:04d}"
    return os.path.join(directory, f"{stem}_{number}{extension}")


def partial_path(path: str) -> str:
    """Where a frame is written before it is complete; renamed to ``path`` when it is. A hidden name
    in the same folder (the rename is atomic), unique per process."""
    directory, name = os.path.split(path)
    stem, extension = os.path.splitext(name)
    return os.path.join(directory, f".{stem}.{os.getpid()}.partial{extension}")


def output_problem(out_path: str) -> str | None:
    """Why no image can be written at ``out_path`` (one line), or None. Checked before anything is
    loaded or rendered: the nearest existing folder on its path must be a folder in which a file can
    be created (tried, not guessed from the permission bits: root may write anywhere but /proc)."""
    out_path = os.path.abspath(out_path)
    if os.path.isdir(out_path):
        return f"--out {out_path} is a folder, not an image file"
    existing = os.path.dirname(out_path)
    while not os.path.lexists(existing):
        existing = os.path.dirname(existing)
    if not os.path.isdir(existing):
        return f"cannot write --out {out_path}: {existing} is a file, not a folder"
    try:
        handle, probe = tempfile.mkstemp(prefix=".relativity-probe-", dir=existing)
    except OSError as error:
        return f"cannot write --out {out_path}: cannot create files in {existing} ({error.strerror})"
    os.close(handle)
    os.remove(probe)
    return None


def format_seconds(seconds: float) -> str:
    if seconds < 60.0:
        return f"{seconds:.1f} s"
    minutes, seconds = divmod(int(round(seconds)), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}h{minutes:02d}m" if hours else f"{minutes}m{seconds:02d}s"


def problem(path: str) -> str | None:
    """Why the file at ``path`` is not a complete PNG or EXR image (one line), or None."""
    try:
        with open(path, "rb") as stream:
            data = stream.read()
    except FileNotFoundError:
        return "missing"
    except OSError as error:
        return f"unreadable: {error.strerror or error}"
    extension = os.path.splitext(path)[1].lower()
    if extension == ".png":
        return _png_problem(data)
    if extension == ".exr":
        return _exr_problem(data)
    return f"not a .png or .exr file: {os.path.basename(path)}"


def is_complete(path: str) -> bool:
    return problem(path) is None


def _png_problem(data):
    if not data.startswith(PNG_SIGNATURE):
        return "not a PNG file (bad signature)"
    position = len(PNG_SIGNATURE)
    header = None
    compressed = []
    while True:
        if position + 8 > len(data):
            return "PNG cut short (no IEND chunk)"
        length, kind = struct.unpack(">I4s", data[position : position + 8])
        end = position + 8 + length + 4
        if end > len(data):
            return f"PNG cut short inside a {kind.decode('latin-1')!r} chunk"
        body = data[position + 8 : position + 8 + length]
        (crc,) = struct.unpack(">I", data[end - 4 : end])
        if zlib.crc32(kind + body) != crc:
            return f"PNG chunk {kind.decode('latin-1')!r} fails its CRC (corrupt)"
        if header is None:
            if kind != b"IHDR" or length != 13:
                return "PNG does not start with IHDR"
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            compressed.append(body)
        position = end
        if kind == b"IEND":
            break
    if position != len(data):
        return "PNG has data after IEND"
    width, height, depth, colour, _, _, interlace = header
    if colour not in PNG_CHANNELS or width == 0 or height == 0:
        return "PNG header is invalid"
    decompressor = zlib.decompressobj()
    try:
        pixels = decompressor.decompress(b"".join(compressed))
    except zlib.error:
        return "PNG image data does not decompress (corrupt)"
    if not decompressor.eof:
        return "PNG image data is cut short"
    if interlace == 0:
        row = math.ceil(width * depth * PNG_CHANNELS[colour] / 8)
        if len(pixels) != height * (1 + row):
            return f"PNG image data holds {len(pixels)} bytes, not {height * (1 + row)}"
    return None


def _exr_attributes(data):
    """The header's attributes {name: (type, value bytes)} and where the offset table starts."""
    attributes = {}
    position = 8
    while True:
        end = data.index(b"\0", position)
        name = data[position:end]
        position = end + 1
        if not name:
            return attributes, position
        end = data.index(b"\0", position)
        kind = data[position:end]
        (size,) = struct.unpack("<i", data[end + 1 : end + 5])
        value = data[end + 5 : end + 5 + size]
        if size < 0 or len(value) != size:
            raise ValueError("attribute cut short")
        attributes[name.decode("latin-1")] = (kind.decode("latin-1"), value)
        position = end + 5 + size


def _exr_problem(data):
    if len(data) < 8 or struct.unpack("<i", data[:4])[0] != EXR_MAGIC:
        return "not an OpenEXR file (bad magic number)"
    (flags,) = struct.unpack("<I", data[4:8])
    if flags & (0x200 | 0x800 | 0x1000):
        return "OpenEXR tiled, deep or multi-part files are not checked"
    try:
        attributes, position = _exr_attributes(data)
        xmin, ymin, xmax, ymax = struct.unpack("<4i", attributes["dataWindow"][1])
        compression = attributes["compression"][1][0]
    except (ValueError, KeyError, struct.error, IndexError):
        return "OpenEXR header is cut short or incomplete"
    if compression not in EXR_LINES_PER_CHUNK or xmax < xmin or ymax < ymin:
        return "OpenEXR header is invalid"
    chunks = math.ceil((ymax - ymin + 1) / EXR_LINES_PER_CHUNK[compression])
    table_end = position + 8 * chunks
    if table_end > len(data):
        return "OpenEXR cut short in its offset table"
    offsets = struct.unpack(f"<{chunks}Q", data[position:table_end])
    last_end = table_end
    for offset in offsets:
        if offset < table_end or offset + 8 > len(data):
            return "OpenEXR cut short (a chunk lies past the end of the file)"
        (size,) = struct.unpack("<i", data[offset + 4 : offset + 8])
        if size < 0 or offset + 8 + size > len(data):
            return "OpenEXR cut short inside a chunk"
        last_end = max(last_end, offset + 8 + size)
    if last_end != len(data):
        return "OpenEXR has data after its last chunk"
    return None
