"""Parameter studies mapped over a dask.distributed cluster, gathered into a pandas DataFrame.

    from dask.distributed import Client
    client = Client("tcp://scheduler:8786")        # or a LocalCluster; None runs serially
    table = femdyn.sweep(study_case, femdyn.grid(length=[0.04, 0.05], integrator=["rk4"]),
                         client=client)

`study_case(**case)` is any function of one case's parameters returning a dict of numbers; it
runs on the workers, which must be able to import femdyn (PYTHONPATH=build/python in their
environment) and the function (cloudpickle ships one defined in a script's __main__). The same
code runs on a LocalCluster and on a multi-machine cluster: only the client changes.
docs/python.md#sweeps and examples/dask_sweep.py.
"""
import itertools


def grid(**axes):
    """The cases of a full factorial design: grid(a=[1, 2], b=["x"]) ->
    [{"a": 1, "b": "x"}, {"a": 2, "b": "x"}] (the first axis varies slowest)."""
    names = list(axes)
    return [dict(zip(names, values)) for values in itertools.product(*axes.values())]


def _apply(case, function):
    return function(**case)


def sweep(function, cases, client=None):
    """function(**case) for every case, on the client's workers (or here, in order, without
    one); a DataFrame with one row per case: the case's columns, then the result's. Rows are in
    the order of `cases` whichever worker ran them. An exception in a case is raised here."""
    import pandas

    cases = [dict(c) for c in cases]
    if client is None:
        results = [function(**c) for c in cases]
    else:
        futures = client.map(_apply, cases, function=function, pure=False)
        results = client.gather(futures)
    rows = []
    for case, result in zip(cases, results):
        clash = set(case) & set(result)
        if clash:
            raise ValueError(f"sweep: the result of case {case} repeats its keys {sorted(clash)}")
        rows.append({**case, **result})
    return pandas.DataFrame(rows)
