"""Saving a figure the way the dressguard commands write their outputs: to a temporary file in the
destination's folder, then a rename over the destination, so that a killed or failing save leaves
the old picture (or none) and never a half-written one under the final name.

    from figure_file import save_figure  # tools/plot's scripts run with this folder on sys.path
    save_figure(fig, OUT, dpi=110)

And reading the scripts' inputs so that a bad one ends the script with one line naming the file
and what was wrong ("eval.json: no participants among its keys (...)", exit 1) rather than a
traceback of a KeyError or a JSONDecodeError:

    d = load_json(PATH)                                   # a JSON object, or exit naming PATH
    with open_input(PATH) as f:                           # a file that is there, or exit
        reader = csv.DictReader(f)
        require_columns(PATH, reader.fieldnames, ["travel_m", "accuracy"])
    require_columns(PATH, d["rows"][0], ["who"], "the keys of the first row")   # JSON keys alike
"""
import json
import os
import tempfile


def open_input(path):
    """open(path) for reading text; a file that cannot be opened exits naming it."""
    try:
        return open(path, newline="")
    except OSError as e:
        raise SystemExit(f"{path}: cannot read it ({e.strerror})") from None


def load_json(path):
    """The JSON object in path; one that cannot be read, is not JSON or not an object exits naming it."""
    with open_input(path) as f:
        try:
            value = json.load(f)
        except ValueError as e:  # json.JSONDecodeError, and text that is not UTF-8
            raise SystemExit(f"{path}: not JSON ({e})") from None
    if not isinstance(value, dict):
        raise SystemExit(f"{path}: not a JSON object (a {type(value).__name__})")
    return value


def require_columns(path, present, names, where="its columns"):
    """Exits naming path and what is missing unless every one of names is among present (a CSV
    header's columns, or a JSON object's keys: say which in `where`)."""
    if present is None:  # csv.DictReader's fieldnames of an empty file
        present = []
    if not isinstance(present, (dict, list, tuple)):
        raise SystemExit(f"{path}: expected an object with {', '.join(names)} ({where}), "
                         f"found a {type(present).__name__}")
    present = list(present)
    missing = [n for n in names if n not in present]
    if missing:
        raise SystemExit(f"{path}: no {', '.join(missing)} among {where} ({', '.join(map(str, present)) or 'none'})")


def save_figure(fig, path, **savefig_kwargs):
    """fig.savefig(path, **savefig_kwargs) through a temporary file beside path and os.replace."""
    folder, name = os.path.split(os.path.abspath(path))
    # The temporary name keeps path's extension: matplotlib picks the format from it.
    fd, tmp = tempfile.mkstemp(prefix="." + name + ".", suffix=os.path.splitext(name)[1], dir=folder)
    os.close(fd)
    try:
        fig.savefig(tmp, **savefig_kwargs)
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)  # mkstemp's 0600 would make the picture private
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise
