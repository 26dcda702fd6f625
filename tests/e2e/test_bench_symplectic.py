"""scripts/bench_symplectic (tools/ropedyn_tools/studies/bench_symplectic.py): its window
table and its growth columns, on records made up so that the answers are known."""
import numpy as np

from ropedyn_tools.studies import bench_symplectic as bs


def records(drift, elastic):
    t = np.arange(0.0, 300.0 + 1e-9, 0.1)
    return {"t": t, "drift": drift(t), "elastic": elastic(t)}


def test_windows_cover_every_record_and_say_a_drift():
    """A steady drift: the largest error grows window by window and the last window holds
    the last record (the error at the end, which the growth column uses too)."""
    r = records(lambda t: -1e-6 * t, lambda t: np.full_like(t, 0.05))
    head, rows = bs.window_rows(20, r)
    assert head.count("|") == 13 and "270-300 s" in head
    largest = [float(x) for x in rows[0].split("|")[3:-1]]
    assert largest[0] < largest[-1] and largest[-1] == 3.0e-4
    assert abs(largest[-1] / bs.upto(r, 30) - 10.0) < 1e-9
    means = [float(x) for x in rows[1].split("|")[3:-1]]
    assert all(a > b for a, b in zip(means, means[1:]))
    # an error at the last record alone shows in the last window
    r["drift"][-1] = 5e-3
    assert bs.window_rows(20, r)[1][0].split("|")[-2].strip() == "5.0e-03"


def test_the_elastic_growth_is_the_last_window_over_the_first():
    r = records(lambda t: 1e-5 * np.sin(t), lambda t: 0.04 + 1e-4 * t * (t > 150))
    first, last = 0.04, 0.04 + 1e-4 * np.arange(270.0, 300.0 + 1e-9, 0.1).mean()
    assert abs(bs.elastic_growth(r) - last / first) < 1e-12
    rows = bs.window_rows(100, r)[1]
    assert rows[2].split("|")[3].strip() == "0.040"


def test_the_ensemble_gives_the_median_range_and_count_of_the_growth(monkeypatch):
    """Each start's growth is the largest error up to the end over the largest up to 30 s;
    the row gives their median, range and how many meet the target of 2, from runs made up
    with growths 1.5, 2, 3 and 5 (and the angle of each start passed to the run)."""
    growths = [1.5, 2.0, 3.0, 5.0]
    angles = []

    def fake_run(exe, work, scene, name, sets):
        k = int(name.rsplit("_", 1)[1])
        angles.append(float(next(s for s in sets if s.startswith("initial.angle_deg="))
                            .split("=")[1]))
        return {"ok": True, **records(lambda t: 1e-5 * np.where(t > 30, growths[k], 1.0)
                                      * np.cos(t), lambda t: 0.04 + 1e-4 * t)}

    monkeypatch.setattr(bs, "run", fake_run)
    (row,) = bs.ensemble_rows("exe", "work", [20], 300.0, len(growths))
    cells = [c.strip() for c in row.split("|")[1:-1]]
    assert cells[:2] == ["20", "4"]
    assert float(cells[3]) == 2.5                       # median of 1.5, 2, 3, 5
    assert cells[4] == "1.50 - 5.00" and cells[5] == "2"
    assert sorted(angles) == [75.0 + k * bs.START_SPACING for k in range(4)]


def test_the_ensemble_takes_the_first_start_from_the_table(monkeypatch):
    """The table's symplectic run is the ensemble's first start (75 degrees): given, it is
    used and not run again."""
    growths = [1.5, 2.0, 3.0, 5.0]
    made = []

    def record(k):
        return {"ok": True, **records(lambda t: 1e-5 * np.where(t > 30, growths[k], 1.0)
                                      * np.cos(t), lambda t: 0.04 + 1e-4 * t)}

    def fake_run(exe, work, scene, name, sets):
        made.append(int(name.rsplit("_", 1)[1]))
        return record(made[-1])

    monkeypatch.setattr(bs, "run", fake_run)
    (row,) = bs.ensemble_rows("exe", "work", [20], 300.0, len(growths), {20: record(0)})
    assert sorted(made) == [1, 2, 3]
    cells = [c.strip() for c in row.split("|")[1:-1]]
    assert float(cells[3]) == 2.5 and cells[4] == "1.50 - 5.00" and cells[5] == "2"


def test_the_tolerance_rows_say_what_a_tighter_rtol_buys(ropedyn_exe, tmp_path, monkeypatch):
    """On the undamped 4-element rope a tighter rtol takes a shorter step (at 1e-5 the
    step rule hands it to SRKN6b) and the largest error falls with it; each row names the
    composition from the run's switch log."""
    monkeypatch.setattr(bs, "TOLERANCE_RTOLS", (1e-3, 1e-5))
    monkeypatch.setattr(bs, "TOLERANCE_T_END", 5.0)
    rows = bs.tolerance_rows(ropedyn_exe, tmp_path)
    cells = [[c.strip() for c in row.split("|")[1:-1]] for row in rows]
    assert [c[0] for c in cells] == ["0.001", "1e-05"]
    assert cells[0][1].startswith("Chin") and cells[1][1].endswith("SRKN6b")
    assert int(cells[1][2]) > int(cells[0][2])
    assert float(cells[1][3]) < 0.1 * float(cells[0][3])


def test_the_growth_over_the_elastic_energy_tells_the_rope_from_a_drift():
    """An error that follows the fast modes' energy (both four times larger after 30 s)
    grows four times but not over that energy (1.0); a steady drift at a constant elastic
    energy grows as much either way; the window table's last row is the ratio."""
    def elastic(t):
        return np.where(t < 30.0, 0.04, 0.16)

    # (a record at 30 s is the second window's and up to 30 s: its error is the first's)
    follows = records(lambda t: 1e-3 * np.where(t <= 30.0, 0.04, 0.16) * np.cos(10 * np.pi * t),
                      elastic)
    assert abs(bs.upto(follows, 300) / bs.upto(follows, 30) - 4.0) < 1e-3
    assert abs(bs.scaled_growth(follows) - 1.0) < 1e-3
    drift = records(lambda t: -1e-6 * (t + 1.0), lambda t: np.full_like(t, 0.05))
    # (the first window ends before 30 s: its largest error is at 29.9 s)
    assert abs(bs.scaled_growth(drift) - 3.01e-4 / 3.09e-5) < 1e-9
    rows = bs.window_rows(20, drift)[1]
    assert rows[3].split("|")[2].strip() == "largest abs error / mean elastic energy"
    assert rows[3].split("|")[-2].strip() == f"{3.01e-4 / 0.05:.1e}"


def test_the_ensemble_counts_the_starts_within_2_over_the_elastic_energy(monkeypatch):
    """The ensemble's last two columns: the growth over the elastic energy (median, range)
    and the starts where it is at most 2: two runs whose error follows the elastic energy
    (1) and two whose error grows three times at a constant elastic energy (3)."""
    def fake_run(exe, work, scene, name, sets):
        def elastic(t):
            return np.where(t < 30.0, 0.04, 0.12) if k < 2 else np.full_like(t, 0.04)
        k = int(name.rsplit("_", 1)[1])
        return {"ok": True, **records(
            lambda t: 1e-5 * np.where(t <= 30.0, 1.0, 3.0) * np.cos(10 * np.pi * t), elastic)}

    monkeypatch.setattr(bs, "run", fake_run)
    (row,) = bs.ensemble_rows("exe", "work", [20], 300.0, 4)
    cells = [c.strip() for c in row.split("|")[1:-1]]
    assert cells[3] == "3.00" and cells[6] == "2.0 (1.0 - 3.0)"
    assert cells[7] == "2.00 (1.00 - 3.00)" and cells[8] == "2"


def test_the_plateau_section_gives_each_growth_and_every_window(monkeypatch):
    """`plateau`: an error that grows with the elastic energy up to 300 s and stays after:
    its growth from 30 s to 300 s is the energy's, from 300 s to the end 1; the windows of
    300 s cover the run and the section is written between its markers with its command."""
    t = np.arange(0.0, 3000.0 + 1e-9, 0.1)
    energy = 0.04 + 0.12 * np.minimum(t, 300.0) / 300.0
    made, written = [], {}

    def fake_run(exe, work, scene, name, sets):
        made.append(sets)
        return {"ok": True, "t": t, "drift": 1e-3 * energy * np.cos(t), "elastic": energy,
                "steps": 123, "cpu": 4.5}

    monkeypatch.setattr(bs, "run", fake_run)
    monkeypatch.setattr(bs, "update_doc", lambda doc, begin, end, block: written.update(
        doc=doc, begin=begin, end=end, block=block))
    assert bs.main(["plateau", "--elements", "20", "--exe", "/bin/true"]) == 0
    assert "solver.t_end=3000" in made[0] and "effects.damping=.false." in made[0]
    # the largest n at rtol 1e-3, and again at the check's rtol
    assert [[x for x in m if x.startswith("solver.rtol=")][-1] for m in made] == \
        ["solver.rtol=0.001", "solver.rtol=1e-05"]
    block = written["block"]
    assert written["doc"] == bs.DOC and block.startswith(bs.PLATEAU_BEGIN)
    assert block.endswith(bs.PLATEAU_END)
    assert "`scripts/bench_symplectic plateau --elements \"20\" --t-end 3000`" in block
    row = next(line for line in block.splitlines() if line.startswith("| 20 | 0.001 | 123 |"))
    cells = [c.strip() for c in row.split("|")[1:-1]]
    growth_30, growth_end = float(cells[7]), float(cells[8])
    assert abs(growth_30 - bs.upto({"t": t, "drift": 1e-3 * energy * np.cos(t)}, 300)
               / bs.upto({"t": t, "drift": 1e-3 * energy * np.cos(t)}, 30)) < 0.05
    assert growth_30 > 3.0 and abs(growth_end - 1.0) < 0.01
    assert cells[9] == "0.100" and cells[10] == "0.160"
    head = next(line for line in block.splitlines() if line.startswith("| n | per window"))
    assert "0-300 s" in head and "2700-3000 s" in head and head.count("|") == 13
    assert "| 20, rtol 1e-05 | mean elastic energy |" in block
