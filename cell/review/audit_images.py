"""Each stop's stereo pair kept in the run directory, for audit and ``holecell remeasure``.

``RUN_DIR/images/stop_000_SPL2_left.png`` and ``..._right.png``: lossless PNG (OpenCV; 8 or
16 bit as the camera gave them, so a pair reads back bit for bit). A resumed run that tries a
stop again writes that stop's pair again (the pair of the stored result). ``--no-images`` on
``holecell run`` keeps none. The summary states how many pairs are kept and their size.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

FOLDER = "images"
SIDES = ("left", "right")


def pair_paths(run_dir: str | Path, stop_index: int, hole_id: str) -> tuple[Path, Path]:
    """The two files of a stop's pair."""
    base = Path(run_dir) / FOLDER / f"stop_{stop_index:03d}_{hole_id}"
    return tuple(base.with_name(f"{base.name}_{s}.png") for s in SIDES)  # type: ignore[return-value]


def save_pair(run_dir: str | Path, stop_index: int, hole_id: str, left: np.ndarray,
              right: np.ndarray) -> int:  # fmt: skip
    """Write a stop's pair (lossless); returns the bytes written."""
    paths = pair_paths(run_dir, stop_index, hole_id)
    paths[0].parent.mkdir(exist_ok=True)
    for path, img in zip(paths, (left, right), strict=True):
        tmp = path.with_name(path.name + ".tmp.png")
        if not cv2.imwrite(str(tmp), img):
            raise OSError(f"{path}: the image could not be written")
        tmp.replace(path)
    return sum(p.stat().st_size for p in paths)


def load_pair(run_dir: str | Path, stop_index: int,
              hole_id: str) -> tuple[np.ndarray, np.ndarray] | None:  # fmt: skip
    """A stop's pair as it was captured, or None when the run kept none for it."""
    paths = pair_paths(run_dir, stop_index, hole_id)
    if not all(p.is_file() for p in paths):
        return None
    imgs = [cv2.imread(str(p), cv2.IMREAD_UNCHANGED) for p in paths]
    if any(i is None for i in imgs):
        return None
    return imgs[0], imgs[1]


def kept(run_dir: str | Path) -> dict[str, int] | None:
    """``{"pairs": n, "bytes": b}`` of the pairs a run kept, None when it kept none."""
    folder = Path(run_dir) / FOLDER
    files = sorted(folder.glob("stop_*_left.png")) if folder.is_dir() else []
    if not files:
        return None
    total = sum(p.stat().st_size for p in folder.glob("stop_*.png"))
    return {"pairs": len(files), "bytes": total}
