"""What the studies share when they write their results into docs/: the machine line, the
time stamp and the generated section between two markers of a Markdown page."""
import datetime
import os
import platform


def machine():
    """'CPU model, N cores, OS release' of this machine."""
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def utc_stamp():
    """The time now, 'YYYY-MM-DD HH:MM UTC'."""
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def splice(text, begin, end, block):
    """text with everything from the marker `begin` to the marker `end` (both included)
    replaced by block (which carries the markers again); None when a marker is missing."""
    if begin in text and end in text:
        return text[:text.index(begin)] + block + text[text.index(end) + len(end):]
    return None


def update_doc(path, begin, end, block, heading="", strip=None, default=None):
    """Write block between the markers of the page at path; the rest of the page is kept.

    A page without the markers gets the block at its end, after a blank line and heading
    (trailing characters in strip removed first; None: white space). default: the text of
    a page that does not exist yet (None: the page must exist)."""
    text = default if default is not None and not path.exists() else path.read_text()
    new = splice(text, begin, end, block)
    if new is None:
        new = text.rstrip(strip) + "\n\n" + heading + block + "\n"
    path.write_text(new)
