"""The scene text of a run (the root attribute `scene`, a Fortran namelist) as a dict of
groups: `parse_namelist(text) -> {group: {key: value}}`."""
import re


def _strip_comment(line):
    """The line without its '!' comment ('!' inside quotes is kept)."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "!":
            return line[:i]
    return line


def _mask_quotes(body):
    """body with the characters inside quotes replaced by '_' (same length)."""
    out, quote = [], None
    for ch in body:
        if quote:
            out.append(ch if ch == quote else "_")
            if ch == quote:
                quote = None
        else:
            if ch in "'\"":
                quote = ch
            out.append(ch)
    return "".join(out)


def _split_commas(value):
    """Split a value at commas outside quotes."""
    masked = _mask_quotes(value)
    parts, start = [], 0
    for i, ch in enumerate(masked):
        if ch == ",":
            parts.append(value[start:i])
            start = i + 1
    parts.append(value[start:])
    return [p.strip() for p in parts if p.strip()]


def _parse_token(token):
    """One namelist value: quoted string, logical, integer or real (NaN allowed)."""
    if token[:1] in "'\"" and token[-1:] == token[:1] and len(token) >= 2:
        return token[1:-1]
    low = token.lower()
    if low in (".true.", "t", ".t."):
        return True
    if low in (".false.", "f", ".f."):
        return False
    try:
        return int(token)
    except ValueError:
        pass
    try:
        return float(low.replace("d", "e"))
    except ValueError:
        return token


def parse_namelist(scene_text):
    """Namelist text -> {group: {key: value}} (lower-case names; 2-vectors as lists).

    Handles the echo written into every run (one key a line) and hand-written files (several
    keys a line, `key(i) = value` components, comments)."""
    body = "\n".join(_strip_comment(line) for line in scene_text.splitlines())
    masked = _mask_quotes(body)
    groups = {}
    for match in re.finditer(r"&(\w+)(.*?)(?:/|&end\b)", masked, re.S | re.I):
        name = match.group(1).lower()
        start, end = match.span(2)
        content, content_masked = body[start:end], masked[start:end]
        keys = list(re.finditer(r"(\w+)\s*(?:\(\s*(\d+)\s*\))?\s*=", content_masked))
        values = groups.setdefault(name, {})
        for k, key in enumerate(keys):
            stop = keys[k + 1].start() if k + 1 < len(keys) else len(content)
            tokens = [_parse_token(t) for t in _split_commas(content[key.end():stop])]
            if not tokens:
                continue
            key_name = key.group(1).lower()
            if key.group(2):
                vector = list(values.get(key_name, [float("nan")] * 2))
                vector[int(key.group(2)) - 1] = tokens[0]
                values[key_name] = vector
            else:
                values[key_name] = tokens[0] if len(tokens) == 1 else tokens
    return groups
