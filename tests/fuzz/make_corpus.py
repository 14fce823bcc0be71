#!/usr/bin/python3
"""Writes the fuzzer's seed corpus (tests/fuzz/corpus) from the small glTF files of
../shared/scenes (khronos, robustness, cornell) and tests/data.

The fuzz target loads from memory and reads nothing from disk, so a .gltf whose buffers are
separate .bin files gets them embedded as base64 data: URIs; files over 200 KB (with their
buffers) are skipped. Run from anywhere; rerun when tests/data changes.
"""
import base64
import json
import pathlib
import shutil
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "scenes"
OUT = ROOT / "tests" / "fuzz" / "corpus"
LIMIT = 200 * 1024


def embed_buffers(path):
    """The .gltf text with every relative buffer uri replaced by a data: URI, or None when a
    buffer is missing or the result exceeds LIMIT."""
    try:
        doc = json.loads(path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError):
        return path.read_text(errors="replace") if path.stat().st_size <= LIMIT else None
    for buffer in doc.get("buffers", []) if isinstance(doc, dict) else []:
        uri = buffer.get("uri", "") if isinstance(buffer, dict) else ""
        if not uri or uri.startswith("data:"):
            continue
        data_path = path.parent / uri
        if not data_path.is_file() or data_path.stat().st_size > LIMIT:
            return None
        encoded = base64.b64encode(data_path.read_bytes()).decode()
        buffer["uri"] = "data:application/octet-stream;base64," + encoded
    text = json.dumps(doc, separators=(",", ":"))
    return text if len(text) <= LIMIT else None


def main():
    sources = [SHARED / "khronos", SHARED / "robustness", SHARED / "cornell", ROOT / "tests" / "data"]
    OUT.mkdir(parents=True, exist_ok=True)
    written = 0
    for source in sources:
        if not source.is_dir():
            print(f"make_corpus: {source} missing, skipped", file=sys.stderr)
            continue
        for path in sorted(source.rglob("*")):
            if path.suffix.lower() not in (".gltf", ".glb") or path.stat().st_size > LIMIT:
                continue
            tag = path.relative_to(source.parent).as_posix().replace("/", "_")
            if path.suffix.lower() == ".glb":
                shutil.copyfile(path, OUT / tag)
            else:
                text = embed_buffers(path)
                if text is None:
                    print(f"make_corpus: {path}: over {LIMIT} bytes with its buffers, skipped")
                    continue
                (OUT / tag).write_text(text)
            written += 1
    total = sum(p.stat().st_size for p in OUT.iterdir())
    print(f"make_corpus: {written} files, {total} bytes in {OUT}")


if __name__ == "__main__":
    main()
