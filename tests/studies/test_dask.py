"""Studies on dask.distributed clusters equal the in-process run."""

import json
import logging

import pytest
from _study_helpers import GRID_6x5, write_study

from impstab.cli import main
from impstab.studies import load_study, open_study, run_study

distributed = pytest.importorskip("distributed")


def _values(store):
    return open_study(store).dataset.drop_attrs()


def _cluster_ready_after(monkeypatch, chunks: int) -> None:
    """The local cluster counts as started only after this process computed ``chunks`` chunks."""
    from impstab.studies import distributed as dist

    calls = [0]

    def ready(self):
        calls[0] += 1
        return calls[0] > chunks and (self.wait() or True)

    monkeypatch.setattr(dist.ClusterStart, "ready", ready)


@pytest.mark.parametrize("early", [0, 3])
def test_local_cluster_of_worker_processes_equals_in_process(tmp_path, capsys, monkeypatch, early):
    # the workers write their chunks (all of them, or those left after this process computed
    # the first ones while the cluster started): the store equals the in-process one
    path = write_study(tmp_path, GRID_6x5, chunk_size=3)
    run_study(load_study(path), tmp_path / "local.zarr")
    _cluster_ready_after(monkeypatch, early)
    code = main(["sweep", str(path), "-o", str(tmp_path / "dask.zarr"), "--workers", "2", "--no-progress",
                 "--min-dask-designs", "0"])
    assert code == 0, capsys.readouterr().err
    assert _values(tmp_path / "dask.zarr").identical(_values(tmp_path / "local.zarr"))
    run = json.loads(open_study(tmp_path / "dask.zarr").dataset.attrs["history"])[-1]
    assert "local cluster of 2 workers (the workers write the chunks" in run["executor"]
    assert run["chunks_computed"] == 12  # chunks of 1 x 3 designs
    assert (f"this process computed {early} chunks while the cluster started" in run["executor"]) == bool(early)


def test_small_studies_stay_in_process_and_say_so(tmp_path, capsys):
    path = write_study(tmp_path, GRID_6x5, chunk_size=5)
    assert main(["sweep", str(path), "-o", str(tmp_path / "s.zarr"), "--workers", "2", "--no-progress"]) == 0
    out = capsys.readouterr()
    assert "30 designs in 6 chunks to compute, too few to share among 2 workers" in out.err
    assert "too few to share" in out.out  # the summary's run row
    run = json.loads(open_study(tmp_path / "s.zarr").dataset.attrs["history"])[-1]
    assert run["executor"].startswith("in-process: 30 designs")


def test_workers_that_cannot_see_the_store_send_their_chunks_back(tmp_path, monkeypatch):
    from impstab.studies import distributed as dist

    path = write_study(tmp_path, GRID_6x5, chunk_size=5)
    run_study(load_study(path), tmp_path / "local.zarr")
    monkeypatch.setattr(dist, "sees_store", lambda target: False)  # as on a cluster without a shared file system
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None,
                                  silence_logs=logging.ERROR) as cluster, distributed.Client(cluster) as client:
        run_study(load_study(path), tmp_path / "c.zarr", client=client, in_process_below=0)
    assert _values(tmp_path / "c.zarr").identical(_values(tmp_path / "local.zarr"))
    run = json.loads(open_study(tmp_path / "c.zarr").dataset.attrs["history"])[-1]
    assert "this process writes the chunks: the workers cannot see the store folder" in run["executor"]


def test_existing_scheduler_by_address(tmp_path, capsys):
    path = write_study(tmp_path, GRID_6x5, chunk_size=10)
    run_study(load_study(path), tmp_path / "local.zarr")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None,
                                  silence_logs=logging.ERROR) as cluster:
        code = main(["sweep", str(path), "-o", str(tmp_path / "remote.zarr"), "--scheduler", cluster.scheduler_address,
                     "--no-progress", "--min-dask-designs", "0"])
    assert code == 0, capsys.readouterr().err
    assert _values(tmp_path / "remote.zarr").identical(_values(tmp_path / "local.zarr"))


def _malloc_env():
    import os

    return os.environ.get("MALLOC_TRIM_THRESHOLD_")


def test_local_cluster_workers_keep_adaptive_malloc(monkeypatch):
    """Dask's nannies set MALLOC_TRIM_THRESHOLD_ (1.5x slower chunks here); ours do not."""
    from impstab.studies.execute import local_cluster

    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    with local_cluster(1, dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        assert set(client.run(_malloc_env).values()) == {None}
    import dask

    default = dask.config.get("distributed.nanny.pre-spawn-environ", {}).get("MALLOC_TRIM_THRESHOLD_")
    if default is None:  # this Dask no longer sets it: nothing to compare with
        return
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=logging.ERROR) as cluster, distributed.Client(cluster) as client:
        assert set(client.run(_malloc_env).values()) == {str(default)}  # what the plain cluster does


def _worker_background(dask_worker):
    import dask

    return ("profile" in dask_worker.periodic_callbacks, dask.config.get("distributed.admin.tick.interval"))


def test_local_cluster_workers_run_without_the_profiler():
    """The 10 ms statistical profiler and the 20 ms tick are off on the workers started here."""
    from impstab.studies.execute import local_cluster

    with local_cluster(1, dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        assert set(client.run(_worker_background).values()) == {(False, "1s")}
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=logging.ERROR) as cluster, distributed.Client(cluster) as client:
        assert set(client.run(_worker_background).values()) == {(True, "20ms")}  # what the plain cluster does
