"""The schema reader (adept_traj.schema.Node) on hand-written documents: values, paths,
labels and messages are compared with literals written out here."""

from __future__ import annotations

import math

import numpy as np
import pytest

from adept_traj.errors import InvalidInputError, ResultFormatError, SceneError
from adept_traj.schema import Node, error_factory


def json_node(value: object) -> Node:
    """A JSON document read with ResultFormatError, whose ``.field`` is the path."""
    return Node(value, "doc.json", ResultFormatError, syntax="JSON")


def toml_node(value: object) -> Node:
    return Node(value, "doc.toml", error_factory(SceneError))


def field_of(call) -> tuple[str | None, str]:
    """``(field, message)`` of the ResultFormatError that ``call()`` raises."""
    with pytest.raises(ResultFormatError) as info:
        call()
    assert info.value.file == "doc.json"
    return info.value.field, str(info.value)


# ------------------------------------------------------------------------ errors and paths
def test_error_factory_names_file_and_field() -> None:
    make = error_factory(SceneError)
    err = make("a.toml", "joint[1].jerk", "must be positive")
    assert isinstance(err, SceneError)
    assert str(err) == "a.toml: field 'joint[1].jerk': must be positive"
    assert str(make("a.toml", None, "not valid TOML")) == "a.toml: not valid TOML"


def test_paths_of_nested_nodes() -> None:
    top = json_node({"a": {"b": [1, 2, {"c": [[0.5]]}]}})
    node = top["a"]["b"].items()[2]["c"]
    assert node.path == "a.b[2].c"
    assert top.path == ""
    assert field_of(lambda: node.string()) == (
        "a.b[2].c",
        "doc.json: field 'a.b[2].c': must be a string; got a list of 1: [[0.5]]",
    )
    assert field_of(lambda: top.items()) == (None, "doc.json: must be a list; got an object")


def test_absent_key_is_missing_unless_defaulted() -> None:
    top = toml_node({"x": 1.0})
    absent = top["y"]
    assert not absent.present
    assert top["x"].present
    assert absent.number("[m]", default=2.5) == 2.5
    assert absent.string(default=None) is None
    assert absent.array((3,), default=None) is None
    assert absent.items(default=[]) == []
    with pytest.raises(SceneError) as info:
        absent.number("[m]", minimum=0.0)
    assert str(info.value) == "doc.toml: field 'y': missing; must be a finite number ≥ 0 [m]"
    with pytest.raises(SceneError, match=r"^doc\.toml: field 'y': missing; must be a table$"):
        absent["z"]


# ------------------------------------------------------------------------ scalars
def test_string() -> None:
    top = json_node({"s": "box", "e": "", "n": None, "i": 3})
    assert top["s"].string() == "box"
    assert top["s"].string(choices=("box", "sphere")) == "box"
    assert top["e"].string() == ""
    assert top["n"].string(null=None) is None
    assert field_of(lambda: top["e"].string(nonempty=True)) == (
        "e",
        "doc.json: field 'e': must be a non-empty string; got the string ''",
    )
    assert field_of(lambda: top["s"].string(choices=("a", "b", "c")))[1].endswith(
        "must be one of 'a', 'b', 'c'; got the string 'box'"
    )
    assert field_of(lambda: top["s"].string(choices=("a", "b")))[1].endswith(
        "must be 'a' or 'b'; got the string 'box'"
    )
    assert field_of(lambda: top["i"].string())[1].endswith("must be a string; got 3")
    assert field_of(lambda: top["n"].string())[1].endswith("must be a string; got null")


def test_strings() -> None:
    top = json_node({"rows": ["vx", "wz"], "bad": ["vx", 1], "twice": ["vx", "vx"], "no": []})
    assert top["rows"].strings() == ("vx", "wz")
    assert top["rows"].strings(choices=("vx", "vy", "wz"), distinct=True) == ("vx", "wz")
    assert top["no"].strings() == ()
    assert field_of(lambda: top["bad"].strings()) == (
        "bad[1]",
        "doc.json: field 'bad[1]': must be a string; got 1",
    )
    assert field_of(lambda: top["rows"].strings(choices=("vx", "vy"))) == (
        "rows[1]",
        "doc.json: field 'rows[1]': must be 'vx' or 'vy'; got the string 'wz'",
    )
    assert field_of(lambda: top["twice"].strings(distinct=True))[1].endswith(
        "field 'twice': must hold distinct strings; got 'vx' more than once"
    )
    assert field_of(lambda: top["no"].strings(min_items=1))[1].endswith(
        "must be a non-empty list; got a list of 0: []"
    )


def test_integer_and_boolean() -> None:
    top = json_node({"i": 3, "f": 3.0, "b": True, "n": None})
    assert top["i"].integer() == 3
    assert type(top["i"].integer()) is int
    assert top["i"].integer(minimum=3, maximum=3) == 3
    assert top["n"].integer(null=None) is None
    assert field_of(lambda: top["f"].integer(null=None))[1].endswith(
        "field 'f': must be an integer or null; got 3.0"
    )
    assert field_of(lambda: top["i"].string(null=None))[1].endswith(
        "field 'i': must be a string or null; got 3"
    )
    assert top["b"].boolean() is True
    for key, got in (("f", "3.0"), ("b", "true"), ("n", "null")):
        assert field_of(lambda key=key: top[key].integer())[1].endswith(
            f"field '{key}': must be an integer; got {got}"
        )
    assert field_of(lambda: top["i"].integer(minimum=4))[1].endswith(
        "must be an integer in [4, ∞]; got 3"
    )
    assert field_of(lambda: top["i"].integer(maximum=2))[1].endswith(
        "must be an integer in [-∞, 2]; got 3"
    )
    assert field_of(lambda: top["i"].boolean())[1].endswith("must be true or false; got 3")


def test_number_ranges_units_and_null() -> None:
    top = toml_node({"zero": 0, "x": 2.5, "inf": math.inf, "nan": math.nan, "b": False})
    assert top["x"].number("[s]") == 2.5
    value = top["zero"].number("[m]", minimum=0.0)
    assert value == 0.0
    assert type(value) is float
    with pytest.raises(SceneError) as info:
        top["zero"].number("[m]", minimum=0.0, strict=True)
    assert str(info.value) == "doc.toml: field 'zero': must be a finite number > 0 [m]; got 0"
    for key, got in (("inf", "inf"), ("nan", "nan"), ("b", "false")):
        with pytest.raises(
            SceneError, match=rf"field '{key}': must be a finite number; got {got}$"
        ):
            top[key].number()
    doc = json_node({"n": None, "s": "1.0"})
    assert doc["n"].number(null=math.inf) == math.inf
    assert doc["n"].number(null=None) is None
    assert field_of(lambda: doc["n"].number()) == (
        "n",
        "doc.json: field 'n': must be a finite number; got null",
    )
    assert field_of(lambda: doc["s"].number("[s]", minimum=-1.0))[1].endswith(
        "must be a finite number ≥ -1 [s]; got the string '1.0'"
    )


# ------------------------------------------------------------------------ arrays
def test_array_values_shape_and_read_only() -> None:
    rows = [[1, 2.5], [-3.0, 4]]
    doc = {"v": [0.5, 1, -2.0], "m": rows, "e": []}
    top = json_node(doc)
    v = top["v"].array((3,), "[m]")
    np.testing.assert_array_equal(v, [0.5, 1.0, -2.0])
    assert v.dtype == np.float64
    assert not v.flags.writeable
    m = top["m"].array((None, 2))
    np.testing.assert_array_equal(m, [[1.0, 2.5], [-3.0, 4.0]])
    assert m.shape == (2, 2)
    assert top["e"].array((None,)).shape == (0,)
    assert top["m"].array((2, None)).shape == (2, 2)
    assert rows == [[1, 2.5], [-3.0, 4]]  # the document is not changed
    assert doc["v"] == [0.5, 1, -2.0]


def test_array_nulls() -> None:
    top = json_node({"lo": [None, -1.0], "hi": [1.0, None], "none": None})
    np.testing.assert_array_equal(top["lo"].array((2,), null=-math.inf), [-math.inf, -1.0])
    np.testing.assert_array_equal(top["hi"].array((2,), null=math.inf), [1.0, math.inf])
    assert top["none"].array((3,), nullable=True) is None
    assert field_of(lambda: top["hi"].array((2,))) == (
        "hi[1]",
        "doc.json: field 'hi[1]': must be a finite number; got null",
    )
    assert field_of(lambda: top["none"].array((3,)))[1].endswith(
        "field 'none': must be a list of 3 finite numbers; got null"
    )


@pytest.mark.parametrize(
    ("value", "shape", "field", "message"),
    [
        (
            [1.0, 2.0],
            (3,),
            "a",
            "must be a list of 3 finite numbers [m]; got a list of 2: [1.0, 2.0]",
        ),
        ("abc", (3,), "a", "must be a list of 3 finite numbers [m]; got the string 'abc'"),
        ([1.0, True, 2.0], (3,), "a[1]", "must be a finite number [m]; got true"),
        ([1.0, [2.0], 2.0], (3,), "a[1]", "must be a finite number [m]; got a list of 1: [2.0]"),
        ([[1.0, 2.0], [3.0]], (None, 2), "a[1]", "must be a list of 2 finite numbers [m]; got"),
        ([[1.0, 2.0], [3.0]], (None, None), "a[1]", "must be a list of 2 finite numbers [m]"),
        ([[1.0, 2.0], [3.0, 4.0]], (3, 2), "a", "must be a list of 3 rows of 2 finite numbers"),
        ([[1.0, 2.0], 3.0], (None, 2), "a[1]", "must be a list of 2 finite numbers [m]; got 3.0"),
        ({"x": 1.0}, (None,), "a", "must be a list of finite numbers [m]; got an object"),
        (1.0, (None,), "a", "must be a list of finite numbers [m]; got 1.0"),
    ],
)
def test_array_errors_name_the_first_bad_entry(
    value: object, shape: tuple, field: str, message: str
) -> None:
    got_field, text = field_of(lambda: json_node({"a": value})["a"].array(shape, "[m]"))
    assert got_field == field
    assert f"doc.json: field '{field}': {message}" in text


def test_array_range_names_the_entry() -> None:
    top = toml_node({"size": [[0.4, 0.2], [0.1, 0.0]]})
    with pytest.raises(SceneError) as info:
        top["size"].array((2, 2), "[m]", minimum=0.0, strict=True)
    assert str(info.value) == (
        "doc.toml: field 'size[1][1]': must be a finite number > 0 [m]; got 0.0"
    )
    assert top["size"].array((2, 2), minimum=0.0).min() == 0.0


@pytest.mark.parametrize("seed", range(5))
def test_array_error_at_a_random_corrupted_cell(seed: int) -> None:
    """Any bad cell of a (6, 4) table, on the fast path or the walk, is named by its index."""
    rng = np.random.default_rng(seed)
    table = rng.normal(size=(6, 4)).tolist()
    i, j = (int(k) for k in rng.integers((6, 4)))
    bad = [True, "1.0", None, [1.0], {"x": 1}, math.nan, -math.inf][seed + rng.integers(3)]
    table[i][j] = bad
    with pytest.raises(SceneError) as info:
        toml_node({"t": table})["t"].array((6, 4))
    assert str(info.value).startswith(f"doc.toml: field 't[{i}][{j}]': must be a finite number;")


# ------------------------------------------------------------------------ tables
def test_check_keys() -> None:
    top = toml_node({"xyz": [0, 0, 0], "z": 1.0})
    with pytest.raises(SceneError) as info:
        top.check_keys(("xyz", "rpy"))
    assert str(info.value) == "doc.toml: field 'z': unknown field; allowed fields: 'xyz', 'rpy'"
    assert top.check_keys(("xyz", "z")) is top


def test_named_tables_label_their_messages() -> None:
    doc = {"link": [{"name": "l1", "solid": [{"name": "s1", "mass": -1.0}]}]}
    top = toml_node(doc)
    ((name, link),) = top["link"].named_tables()
    assert name == "l1"
    ((_, solid),) = link["solid"].named_tables()
    with pytest.raises(SceneError) as info:
        solid["mass"].number("[kg]", minimum=0.0, strict=True)
    assert str(info.value) == (
        "doc.toml: field 'link[0].solid[0].mass': must be a finite number > 0 [kg]; got -1.0 "
        "(in link 'l1', solid 's1')"
    )
    assert top["frame"].named_tables() == []
    with pytest.raises(SceneError) as info:
        toml_node({"joint": {"name": "a"}})["joint"].named_tables()
    assert str(info.value) == (
        "doc.toml: field 'joint': must be an array of tables ([[joint]]); got a table"
    )
    assert field_of(lambda: json_node({"joint": [1]})["joint"].named_tables()) == (
        "joint",
        "doc.json: field 'joint': must be a list of objects; got a list of 1: [1]",
    )
    with pytest.raises(SceneError, match=r"field 'joint\[1\]\.name': missing; must be a non-empty"):
        toml_node({"joint": [{"name": "a"}, {}]})["joint"].named_tables()


def test_build_turns_input_errors_into_the_node_error() -> None:
    node = toml_node({"o": {"r": 0.0}})["o"].labelled("obstacle 'x'")

    def make(r: float) -> float:
        if r <= 0:
            raise InvalidInputError(f"radius must be > 0 [m]; got {r}")
        return r

    assert node.build(make, 1.0) == 1.0
    with pytest.raises(SceneError) as info:
        node.build(make, 0.0)
    assert (
        str(info.value) == "doc.toml: field 'o': radius must be > 0 [m]; got 0.0 (in obstacle 'x')"
    )
    with pytest.raises(KeyError):  # not an input error: a bug, left alone
        node.build(lambda: {}["k"])


def test_from_json() -> None:
    top = Node.from_json('{"a": [1, 2.5]}', "r.json", ResultFormatError)
    assert top.syntax == "JSON"
    np.testing.assert_array_equal(top["a"].array((2,)), [1.0, 2.5])
    with pytest.raises(
        ResultFormatError,
        match=r"^r\.json: NaN is not a JSON number \(the files write ±inf as null\)$",
    ):
        Node.from_json('{"a": NaN}', "r.json", ResultFormatError)
    with pytest.raises(ResultFormatError) as info:
        Node.from_json('{"a": 1,\n "b" 2}', "r.json", ResultFormatError)
    assert info.value.field is None
    assert str(info.value).startswith("r.json: not valid JSON: Expecting ':' delimiter (line 2,")


def test_describe_shortens_long_values() -> None:
    text = "x" * 50
    assert toml_node({"s": text})["s"].describe() == f"the string {'x' * 40!r}…"
    assert toml_node({"v": list(range(40))})["v"].describe() == "a list of 40"
    assert toml_node({"v": [1, 2]})["v"].describe() == "a list of 2: [1, 2]"
    assert toml_node({})["v"].describe() == "<absent>"
