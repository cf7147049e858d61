"""halfback.emit's material name cannot inject markup (Mitsuba 3) or statements (pbrt-v4)."""
import xml.etree.ElementTree as ET

import pytest

import halfback


def test_a_mitsuba_name_is_escaped_into_its_id():
    hostile = 'x"/><bsdf type="evil'
    text = halfback.emit("ggx:alpha=0.3,f0=0.5", "mitsuba3", name=hostile)
    scene = ET.fromstring(text.split("?>", 1)[1])
    bsdfs = scene.findall(".//bsdf")
    assert [b.get("type") for b in bsdfs] == ["principled"]
    assert scene.find("bsdf").get("id") == hostile


@pytest.mark.parametrize("name", ["x\nAttributeBegin", 'x" "string type" "evil', "a\\b", "\x1b", ""])
def test_a_pbrt_name_that_would_end_its_quotes_or_line_is_refused(name):
    with pytest.raises(ValueError, match="material name"):
        halfback.emit("ggx:alpha=0.3,f0=0.5", "pbrt-v4", name=name)


def test_a_newline_is_refused_in_mitsuba_names_too():
    with pytest.raises(ValueError, match="control character"):
        halfback.emit("lambert", "mitsuba3", name="a\nb")
