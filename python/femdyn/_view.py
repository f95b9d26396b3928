"""Model.view: the 3-D page of `femdyn view` from Python, shown inline in Jupyter (docs/view.md)."""
import csv
import html
import io
import os
import tempfile


def _trajectory_csv(model, traj):
    """The rows femdyn.simulate returns (a dict of t, q, kinetic, potential, work), or
    Simulator.run's (t, q, qd, work: the energies are computed here from q and qd), as the
    trajectory CSV `femdyn simulate --out` writes (io/trajectory_csv.hpp)."""
    if "kinetic" not in traj and "qd" in traj:
        energies = [model.energy(q, qd) for q, qd in zip(traj["q"], traj["qd"])]
        traj = dict(traj, kinetic=[e["kinetic"] for e in energies],
                    potential=[e["potential"] for e in energies])
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["t"] + ["q_" + c for c in model.configuration] +
                    ["kinetic", "potential", "work"])
    q = traj["q"]
    for k, t in enumerate(traj["t"]):
        writer.writerow([repr(float(t))] + [repr(float(x)) for x in q[k]] +
                        [repr(float(traj[e][k])) for e in ("kinetic", "potential", "work")])
    return out.getvalue()


def _in_notebook():
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


def view(self, traj=None, q=None, path=None, force=False):
    """Writes the model's self-contained 3-D page (as `femdyn view`) and returns its path.

    traj: a trajectory CSV file (`femdyn simulate --out`), or the dict femdyn.simulate or
    Simulator.run returns;
    q: one posture (n_q values) instead; neither: the neutral configuration. path: the HTML file
    to write (default: a new file in a temporary directory); an existing file is replaced only
    with force=True. In a Jupyter kernel the page is also shown inline (an iframe holding it)."""
    if traj is not None and q is not None:
        raise ValueError("traj and q: give one of them")
    if path is None:
        path = os.path.join(tempfile.mkdtemp(prefix="femdyn-view-"), "view.html")
    path = os.fspath(path)
    if os.path.exists(path) and not force:
        raise FileExistsError(f"{path}: exists (use force=True to replace it)")
    if traj is None or isinstance(traj, (str, os.PathLike)):
        self._write_view(path, force, traj_path=None if traj is None else os.fspath(traj), q=q)
    else:
        self._write_view(path, force, traj_text=_trajectory_csv(self, traj))
    if _in_notebook():
        from IPython.display import HTML, display
        with open(path, encoding="utf-8") as page:
            srcdoc = html.escape(page.read(), quote=True)
        display(HTML(f'<iframe srcdoc="{srcdoc}" style="width:100%;height:620px;border:0">'
                     "</iframe>"))
    return path
