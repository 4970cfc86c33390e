"""A cgroup v2 folder is set up as the kernel reads it: a memory limit always, a CPU limit only when asked for one.

The machines the suite runs on may have v1 or no writable cgroup at all, so the v2 branch is exercised on a
plain folder standing in for the parent cgroup (the files it writes are what the kernel would read)."""

from labkit.grading.sandbox import cgroup


def _v2_under(tmp_path, monkeypatch):
    monkeypatch.setattr(cgroup, "_candidates", lambda: [("v2", tmp_path)])


def test_a_grading_process_cgroup_gets_memory_and_no_cpu_limit(tmp_path, monkeypatch):
    _v2_under(tmp_path, monkeypatch)
    group = cgroup.create(512 * 1024**2, label="labkit-grader", cores=None)
    assert group is not None
    (folder,) = tmp_path.iterdir()
    assert (folder / "memory.max").read_text() == str(512 * 1024**2)
    assert (folder / "memory.swap.max").read_text() == "0"
    assert not (folder / "cpu.max").exists()


def test_a_sandbox_cgroup_gets_its_cores(tmp_path, monkeypatch):
    _v2_under(tmp_path, monkeypatch)
    assert cgroup.create(1024**3, cores=1.5) is not None
    (folder,) = tmp_path.iterdir()
    assert (folder / "cpu.max").read_text() == "150000 100000"
