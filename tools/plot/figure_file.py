"""Saving a figure the way the dressguard commands write their outputs: to a temporary file in the
destination's folder, then a rename over the destination, so that a killed or failing save leaves
the old picture (or none) and never a half-written one under the final name.

    from figure_file import save_figure  # tools/plot's scripts run with this folder on sys.path
    save_figure(fig, OUT, dpi=110)
"""
import os
import tempfile


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
