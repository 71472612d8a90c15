"""Named controller variants of aic_compare.py: a base configuration plus KEY=VALUE overrides.

One variant is one line:

    NAME=BASE[+OVERLAY...][:KEY=VALUE,KEY=VALUE,...]

NAME a column title (letters, digits, '_', '-', '.', '+'); BASE a controller YAML: a path (absolute,
or relative to the current directory or to the package's folder) or a bare name, config/NAME.yaml
of the package (e.g. "default", "thesis_equivalent"); each OVERLAY a YAML found the same way whose
keys apply after BASE, in the file's order, as the node stacks an overlay on its configuration
(default+goal_model: config/goal_model.yaml over config/default.yaml); the overrides as
closed_loop_run's --aic-set takes them, applied in order after BASE and the overlays, commas inside
[...] kept (var_mu=[1.5,2,4,8,16]). KEY*=FACTOR scales the key's value in BASE and the overlays
(BASE's effective value: BASE over the schema's defaults, `aic_params --yaml --config BASE`, unless
an overlay sets it) by FACTOR: k_a*=0.001.

A variants file holds one such line per variant; blank lines and lines starting with '#' are
skipped.
"""
import os
import re

from ..common.tables import fmt_value

_NAME = re.compile(r"^[A-Za-z0-9_.+-]+$")


class VariantError(ValueError):
    """A variant line or file that cannot be read; the message names it."""


class Variant(object):
    """One variant: ``name``, ``config`` (the base YAML's absolute path), ``sets`` (KEY=VALUE
    strings for --aic-set, scaled keys resolved), ``line`` (the line it was read from)."""

    def __init__(self, name, config, sets, line):
        self.name, self.config, self.sets, self.line = name, config, list(sets), line

    def __repr__(self):
        return "Variant(%r, %r, %r)" % (self.name, self.config, self.sets)


def split_sets(text):
    """``text`` ("K=V,K=[a,b],...") split at the commas outside brackets: a list of stripped,
    non-empty items."""
    items, depth, cur = [], 0, ""
    for ch in text:
        depth += {"[": 1, "]": -1}.get(ch, 0)
        if ch == "," and depth == 0:
            items.append(cur)
            cur = ""
        else:
            cur += ch
    items.append(cur)
    return [i.strip() for i in items if i.strip()]


def resolve_config(base, root):
    """The absolute path of the base configuration ``base``: a path that exists as given or under
    ``root`` (the package's folder), else ``root``/config/``base``.yaml. Raises VariantError when
    none exists."""
    for c in (base, os.path.join(root, base), os.path.join(root, "config", base + ".yaml")):
        if os.path.isfile(c):
            return os.path.abspath(c)
    raise VariantError("no configuration %r (neither a file nor config/%s.yaml of %s)" % (base, base, root))


def overlay_sets(path):
    """The keys of the overlay YAML ``path`` as KEY=VALUE overrides, in the file's order, and as a
    dict key -> value: booleans as true / false, numbers and lists as fmt_value(). Raises
    VariantError when the file cannot be read or is not a mapping of keys."""
    import yaml
    try:
        with open(path) as f:
            values = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        raise VariantError("overlay %s: %s" % (path, e))
    if values is None:
        values = {}
    if not isinstance(values, dict):
        raise VariantError("overlay %s: not a mapping of keys to values" % path)

    def text(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        return fmt_value(v)

    return ["%s=%s" % (k, text(v)) for k, v in values.items()], values


def parse(line, root, effective=None):
    """One variant line (module docstring) as a Variant. ``root``: the package's folder;
    ``effective(config_path)``: the base's every key -> value (cli.Tool.config), needed only for
    KEY*=FACTOR. Raises VariantError naming the line."""
    text = line.strip()
    name, eq, rest = text.partition("=")
    name = name.strip()
    if not eq or not _NAME.match(name) or not rest.strip():
        raise VariantError("variant %r: expected NAME=BASE[:KEY=VALUE,...]" % line)
    base, _, sets_text = rest.partition(":")
    stack = [b.strip() for b in base.split("+")]
    config = resolve_config(stack[0], root)
    sets = []
    overlaid = {}
    for overlay in stack[1:]:
        more, values = overlay_sets(resolve_config(overlay, root))
        sets += more
        overlaid.update(values)
    values = None
    for item in split_sets(sets_text):
        key, eq, value = item.partition("=")
        if not eq or not key.strip() or not value.strip():
            raise VariantError("variant %r: override %r is not KEY=VALUE or KEY*=FACTOR" % (line, item))
        key = key.strip()
        if key.endswith("*"):
            key = key[:-1].strip()
            if effective is None:
                raise VariantError("variant %r: %s*= needs the base's values" % (line, key))
            values = values if values is not None else dict(effective(config), **overlaid)
            if key not in values or isinstance(values[key], (bool, str, list)):
                raise VariantError("variant %r: %s is not a numeric key of %s" % (line, key, config))
            try:
                factor = float(value)
            except ValueError:
                raise VariantError("variant %r: factor %r of %s is not a number" % (line, value, key))
            sets.append("%s=%s" % (key, fmt_value(float(values[key]) * factor)))
        else:
            sets.append("%s=%s" % (key, value.strip()))
    return Variant(name, config, sets, text)


def read_file(path, root, effective=None):
    """The variants of the file ``path`` (module docstring), in order (parse() per line). Raises
    VariantError naming the file and line, OSError when it cannot be read."""
    out = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            try:
                out.append(parse(line, root, effective))
            except VariantError as e:
                raise VariantError("%s:%d: %s" % (path, n, e))
    return out


def check_names(variants):
    """Raise VariantError when ``variants`` is empty or two share a name, or one is named stock
    or floor (the reference columns)."""
    if not variants:
        raise VariantError("no variant given (--variant NAME=BASE[:K=V,...] or --variants FILE)")
    seen = set()
    for v in variants:
        if v.name in seen or v.name in ("stock", "floor"):
            raise VariantError("variant name %r used twice or reserved (stock, floor)" % v.name)
        seen.add(v.name)
