"""tools/ropedyn_tools/studies/stability_metrics.py: which end's speed the hard-scenes table
reports, from the effective scene a run's file holds."""
from ropedyn_tools.studies.stability_metrics import lower_end_free


def scene(bottom, release):
    """The lines of an effective scene's &supports that decide it."""
    return (f"&supports\n    top = 'pinned'\n    bottom = '{bottom}'\n"
            f"    top_release_time = -1.0\n    bottom_release_time = {release}\n/\n")


def test_a_free_or_released_lower_end_is_free():
    assert lower_end_free(scene("free", -1.0))
    # the folded ropes: held, released at the start (their tip speed was the midpoint's)
    assert lower_end_free(scene("pinned", 0.0))
    assert lower_end_free(scene("clamped", 2.5))


def test_an_end_held_throughout_is_not():
    assert not lower_end_free(scene("pinned", -1.0))
    assert not lower_end_free(scene("clamped", -1.0))
