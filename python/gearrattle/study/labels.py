"""Figure labels as an engineer reads them: a quantity's name in words from its description in
the model description, and its unit from the contract, printed the usual way (rad/s², °C)."""

import re

# The contract's unit strings (FMI 2.0 names, ASCII) as they are printed on a figure.
DISPLAY = {"rad/s2": "rad/s²", "m/s2": "m/s²", "kg.m2": "kg·m²", "N.m": "N·m",
           "N.m/rad": "N·m/rad", "N.m.s": "N·m·s", "N.s/m": "N·s/m", "degC": "°C",
           "rev/min": "rpm", "rev/min/s": "rpm/s", "m2/s": "m²/s"}


def unit(var):
    """The printed unit of a variable (None without one); a rate of impacts is impacts/s."""
    if var is None or not var.unit:
        return None
    if var.unit == "1/s" and "impact" in var.name:
        return "impacts/s"
    return DISPLAY.get(var.unit, var.unit)


def variable(model, name):
    """The model's variable of this name (parameter or output), or None."""
    return model.parameters.get(name) or model.outputs.get(name)


def axis(model, name):
    """An axis or colour-bar label: 'rpm [rpm]', 'T_oil [°C]', 'stat_regime' (no unit)."""
    u = unit(variable(model, name))
    return f"{name} [{u}]" if u else name


def words(model, name):
    """A quantity in words: its description up to the first ':' or ' (' ('Rattle power'), with
    the gear it belongs to; its name where the model does not describe it."""
    var = variable(model, name)
    text = re.split(r":| \(", var.description, maxsplit=1)[0] if var and var.description else ""
    text = re.sub(r" (in|over) the window$", "", text).strip() or name
    gear = re.match(r"gear\[(\d+)\]\.", name)
    return f"gear {gear[1]}: {text}" if gear else text


def phrase(model, name):
    """words() inside a sentence: its first letter in lower case, unless it opens an acronym
    (RMS stays RMS)."""
    text = words(model, name)
    return text if text[1:2].isupper() else text[:1].lower() + text[1:]
