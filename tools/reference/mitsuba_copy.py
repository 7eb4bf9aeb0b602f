"""A copy of a Mitsuba scene file that Mitsuba 3 loads, at a chosen film size, placed anywhere.

The edits ../shared/data/mitsuba/README.md lists for the 0.5/0.6 files (`<lookAt>` ->
`<lookat>`, `high_quality_edges` removed), the film's `width` and `height` set to `size`, and
every relative file name (`<string name="filename">`, `<include filename>`) made absolute, so
that the copy can live outside the scene's folder and both renderers read the same file.
"""
import re
from pathlib import Path


def patched_text(src: Path, size: int) -> str:
    src = Path(src).resolve()
    text = src.read_text()
    text = text.replace("<lookAt", "<lookat").replace("</lookAt>", "</lookat>")
    text = re.sub(r'<boolean name="high_?[qQ]uality_?[eE]dges"[^>]*/>', "", text)
    text = re.sub(r'(<integer name="width" value=")\d+(")', rf"\g<1>{size}\2", text)
    text = re.sub(r'(<integer name="height" value=")\d+(")', rf"\g<1>{size}\2", text)

    def absolute(m: re.Match) -> str:
        name = m.group(2)
        if "$" in name or Path(name).is_absolute():
            return m.group(0)
        return m.group(1) + str(src.parent / name) + m.group(3)

    text = re.sub(r'(name="filename"\s+value=")([^"]+)(")', absolute, text)
    text = re.sub(r'(<include\s+filename=")([^"]+)(")', absolute, text)
    return text


def write_copy(src: Path, size: int, dest: Path) -> Path:
    dest = Path(dest)
    dest.write_text(patched_text(src, size))
    return dest
