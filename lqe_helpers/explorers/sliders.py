"""Sliders with the pack's conventions: symbol and unit, no live drag, no silent clipping.

Every explorer makes its sliders here. A slider refuses a range it could not show
(empty, infinite), a starting value ipywidgets would clip into the range without a
word, and a readout it could not read back; :func:`starting_value` refuses a
scenario value outside a slider's range instead of clipping it. A value set from code
outside the range (``slider.value = -2``, meant as the exponent of a logarithmic
slider whose value is P0 itself) raises instead of being clipped to the nearest end.
"""

from __future__ import annotations

import math

import ipywidgets as widgets
import traitlets

from .. import validation

#: Relative slack at the ends of a range for a value set by the browser, whose sliders
#: compute the ends (10 ** exponent) in their own floating point.
_END_SLACK = 1e-9


def _in_range(slider: widgets.ValueWidget, value: float, low: float, high: float,
              hint: str) -> float:
    """``value`` if it lies in ``[low, high]`` (within :data:`_END_SLACK`), else TraitError.

    ipywidgets clips such a value to the nearest end without a word.
    """
    slack = _END_SLACK * max(abs(low), abs(high))
    if not low - slack <= value <= high + slack:
        raise traitlets.TraitError(
            f"the slider {slider.description!r} takes values in [{low:.6g}, {high:.6g}], "
            f"got {value:.6g}{hint}")
    return min(max(value, low), high)


class _FloatSlider(widgets.FloatSlider):
    """A FloatSlider that refuses a value outside its range instead of clipping it."""

    @traitlets.validate("value")
    def _validate_value(self, proposal: traitlets.Bunch) -> float:
        return _in_range(self, proposal["value"], self.min, self.max, "")


class _FloatLogSlider(widgets.FloatLogSlider):
    """A FloatLogSlider that refuses a value outside its range instead of clipping it.

    Its value is the quantity itself (P0 in cm²), not the exponent the slider moves.
    """

    @traitlets.validate("value")
    def _validate_value(self, proposal: traitlets.Bunch) -> float:
        return _in_range(self, proposal["value"], self.base ** self.min, self.base ** self.max,
                         f": the value itself, not its exponent (1e-2 for "
                         f"{self.base:g}^-2)")


def _check_readout_format(readout_format: str) -> None:
    """Reject readout formats the slider's text box cannot read back.

    ipywidgets parses text typed into the readout with ``parseFloat``, which stops at
    a thousands separator: "1,396" would be read as 1.
    """
    if "," in readout_format or "_" in readout_format:
        raise ValueError(
            f"readout_format must not group thousands (',' or '_'), got {readout_format!r}: "
            "the slider could not read its own readout back"
        )


def _check_range(description: str, value: float, low: float,
                 high: float) -> tuple[float, float, float]:
    """``value``, ``low`` and ``high`` as floats if finite with ``low < high`` and
    ``low <= value <= high``; otherwise a ``ValueError`` naming the slider.

    ipywidgets would instead clip a value outside the range without a word, so a
    slider could silently start somewhere its caller never asked for.
    """
    low = validation.finite_number("low", low)
    high = validation.finite_number("high", high)
    value = validation.finite_number("value", value)
    if not low < high:
        raise ValueError(
            f"low must be < high for the slider {description!r}, got low = {low:.12g}, "
            f"high = {high:.12g}"
        )
    if not low <= value <= high:
        raise ValueError(
            f"value must lie in the slider's range [low, high] = [{low:.12g}, {high:.12g}] "
            f"for the slider {description!r}, got {value:.12g}"
        )
    return value, low, high


def float_slider(description: str, value: float, low: float, high: float, step: float,
                 readout_format: str = ".2f") -> widgets.FloatSlider:
    """A linear slider with the pack's conventions (symbol and unit, no live drag).

    Parameters
    ----------
    description : str
        Symbol and unit shown beside the slider, e.g. ``"σ_v (cm)"``.
    value : float
        Starting value, ``low <= value <= high``.
    low, high : float
        Ends of the range, ``low < high``.
    step : float
        Distance between slider positions, > 0.
    readout_format : str
        Python format of the readout; no thousands separators.

    Raises
    ------
    ValueError
        If a number is not finite, the range is empty, ``step <= 0``, ``value`` lies
        outside ``[low, high]`` or the readout could not be read back.
    traitlets.TraitError
        Later, if code sets the slider's value outside ``[low, high]``.
    """
    _check_readout_format(readout_format)
    value, low, high = _check_range(description, value, low, high)
    step = validation.positive("step", step)
    return _FloatSlider(
        value=value, min=low, max=high, step=step, description=description,
        readout_format=readout_format, continuous_update=False,
        style={"description_width": "initial"}, layout=widgets.Layout(width="340px"),
    )


def log_slider(description: str, value: float, low: float, high: float,
               steps_per_decade: int = 4, readout_format: str = ".3g") -> widgets.FloatLogSlider:
    """A base-10 logarithmic slider from ``low`` to ``high`` (e.g. P0 in cm²).

    Parameters
    ----------
    description : str
        Symbol and unit shown beside the slider, e.g. ``"P0 (cm²)"``.
    value : float
        Starting value, ``low <= value <= high``.
    low, high : float
        Ends of the range, ``0 < low < high``.
    steps_per_decade : int
        Slider positions per factor of ten, a whole number >= 1.
    readout_format : str
        Python format of the readout; no thousands separators.

    Raises
    ------
    ValueError
        If a number is not finite, ``low <= 0``, the range is empty, ``value`` lies
        outside ``[low, high]``, ``steps_per_decade`` is not a whole number >= 1 or
        the readout could not be read back.
    traitlets.TraitError
        Later, if code sets the slider's value outside ``[low, high]`` (an exponent, say).
    """
    _check_readout_format(readout_format)
    value, low, high = _check_range(description, value, low, high)
    if low <= 0:
        raise ValueError(
            f"low must be > 0 for the logarithmic slider {description!r}, got {low:.12g}"
        )
    steps_per_decade = validation.count("steps_per_decade", steps_per_decade, minimum=1)
    return _FloatLogSlider(
        value=value, base=10, min=math.log10(low), max=math.log10(high),
        step=1.0 / steps_per_decade, description=description, readout_format=readout_format,
        continuous_update=False, style={"description_width": "initial"},
        layout=widgets.Layout(width="340px"),
    )


def starting_value(field: str, value: float, low: float, high: float, unit: str) -> float:
    """The scenario's ``field`` as a slider's starting value, if it lies in ``[low, high]``.

    An explorer starts its slider at a value of the scenario it is given. A value
    outside the slider's range is refused rather than clipped into it, so the
    figure never silently shows another value than the scenario asks for.

    Parameters
    ----------
    field : str
        Name of the scenario attribute, for the message (e.g. ``"sigma_v"``).
    value : float
        Its value.
    low, high : float
        The slider's range.
    unit : str
        Unit of all three, for the message (e.g. ``"cm"``).

    Raises
    ------
    ValueError
        If ``value`` lies outside ``[low, high]``.
    """
    value = float(value)
    if not low <= value <= high:
        raise ValueError(
            f"scenario.{field} must lie in the explorer's slider range "
            f"[{low:.12g}, {high:.12g}] {unit}, got {value:.12g} {unit}"
        )
    return value
