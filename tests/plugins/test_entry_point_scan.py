"""geobrep's own entry-point scan finds exactly what importlib.metadata finds.

:mod:`geobrep.host._entry_points` reads the distributions on ``sys.path`` itself (no
importlib.metadata, no email parser); each test compares its answer with
``importlib.metadata.entry_points(group=...)`` and ``Distribution.name``/``version`` on the same
``sys.path``: the installed distributions of the test venv, and fake ones made in a tmp folder
(duplicates, .egg-info folders and files, odd entry_points.txt and METADATA headers).
"""

from __future__ import annotations

import importlib.metadata as metadata
import subprocess
import sys
import warnings
import zipfile
from pathlib import Path
from typing import Any

import pytest

from geobrep.host import _entry_points as scan
from geobrep.host.loader import ENTRY_POINT_GROUP, discover_entry_points


def described(entry_points: Any) -> list[tuple[Any, ...]]:
    """What the loader uses of each entry point, with its distribution's name and version."""
    return [
        (ep.name, ep.value, ep.group, ep.module, ep.attr, *scan.distribution(ep))
        for ep in entry_points
    ]


@pytest.fixture(autouse=True)
def only_the_path_finder(monkeypatch: pytest.MonkeyPatch) -> None:
    """The import system as a fresh interpreter has it: the path finder the only one that finds
    distributions. A package imported earlier in the test run may change that: the
    ``importlib_metadata`` backport adds its own finder and deletes the path finder's
    ``find_distributions``. The scan then leaves the answer to importlib.metadata (tested
    below), which the other tests would not see."""
    from importlib.machinery import PathFinder

    if not hasattr(PathFinder, "find_distributions"):

        def find_distributions(*args: Any, **kwargs: Any) -> Any:
            return metadata.MetadataPathFinder.find_distributions(*args, **kwargs)

        monkeypatch.setattr(
            PathFinder, "find_distributions", staticmethod(find_distributions), raising=False
        )
    monkeypatch.setattr(
        sys,
        "meta_path",
        [
            finder
            for finder in sys.meta_path
            if finder is PathFinder or getattr(finder, "find_distributions", None) is None
        ],
    )


def groups() -> list[str]:
    return sorted(metadata.entry_points().groups)


def same_as_importlib(group: str, *, fast: bool = True) -> None:
    """The scan's answer for ``group`` is importlib.metadata's (its own, not its fallback's,
    when ``fast``)."""
    expected = described(metadata.entry_points(group=group))
    if fast:
        assert described(scan._scan(group)) == expected, group
    assert described(scan.entry_points(group=group)) == expected, group


def test_every_group_of_the_installed_distributions() -> None:
    found = groups()
    assert ENTRY_POINT_GROUP in found
    for group in found:
        same_as_importlib(group)
    assert len(scan._distributions()) == len({d._normalized_name for d in metadata.distributions()})  # type: ignore[attr-defined]


def test_the_loader_sees_geobrep_s_own_plugins() -> None:
    eps = discover_entry_points()
    assert {ep.name for ep in eps} >= {"native", "gocad", "clip", "blocks"}
    assert all(scan.distribution(ep)[0] == "geobrep" for ep in eps if scan.is_builtin(ep))
    assert all(isinstance(ep, scan.EntryPoint) for ep in eps)


def dist_info(
    folder: Path,
    stem: str,
    entry_points: str | None,
    metadata_text: str,
    *,
    metadata_file: str = "METADATA",
) -> Path:
    path = folder / stem
    path.mkdir(parents=True)
    (path / metadata_file).write_text(metadata_text, encoding="utf-8")
    if entry_points is not None:
        (path / "entry_points.txt").write_text(entry_points, encoding="utf-8")
    return path


ENTRY_POINTS = """\
# a comment
[geobrep.plugins]
fake_one = geobrep_fake_good
  fake_two=geobrep_fake_good:Plugin.inner  [extra1, extra2]
fake_three =   geobrep_fake_good :  attr

[console_scripts]
fake-tool = geobrep_fake_good:main
[geobrep.plugins]
fake_again = geobrep_fake_duplicate
"""


@pytest.fixture
def fake_site(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    """Two folders put first on sys.path, with fake distributions of every kind, and a third
    one last (after the installed geobrep)."""
    first, second, last = tmp_path / "first", tmp_path / "second", tmp_path / "last"
    dist_info(first, "Fake_Plugin-1.0.dist-info", ENTRY_POINTS, "Name: Fake.Plugin\nVersion: 1.0\n")
    # the same distribution once more, later on sys.path and in the same folder: the first
    # wins (in the folder: the first listed, whichever that is)
    dist_info(
        second,
        "fake_plugin-2.0.dist-info",
        "[geobrep.plugins]\nshadowed = geobrep_fake_good\n",
        "Name: fake-plugin\nVersion: 2.0\n",
    )
    dist_info(
        first,
        "fake.plugin-3.0.dist-info",
        "[geobrep.plugins]\nshadowed_too = geobrep_fake_good\n",
        "Name: fake-plugin\nVersion: 3.0\n",
    )
    # an .egg-info folder (PKG-INFO), with headers the email parser reads in its own way
    dist_info(
        first,
        "eggy-0.1-py3.11.egg-info",
        "[geobrep.plugins]\neggy = geobrep_fake_good\n",
        "Metadata-Version: 1.1\nname:\t eggy  \nSummary: a\n  folded summary\n"
        "Version: 0.1\nName: not-this-one\n\nName: body, not a header\n",
        metadata_file="PKG-INFO",
    )
    # an .egg-info file (no folder), METADATA without a final newline, no entry points
    (first / "single-0.2.egg-info").write_text("Name: single\nVersion: 0.2", encoding="utf-8")
    dist_info(second, "quiet-1.0.dist-info", None, "Name: quiet\nVersion: 1.0")
    # a distribution named geobrep again, after the installed one: it must not shadow it
    dist_info(
        last,
        "geobrep-9.9.dist-info",
        "[geobrep.plugins]\nimpostor = geobrep_fake_good\n",
        "Name: geobrep\nVersion: 9.9\n",
    )
    monkeypatch.syspath_prepend(str(second))
    monkeypatch.syspath_prepend(str(first))
    monkeypatch.setattr(sys, "path", [*sys.path, str(last)])
    return first, last


def test_fake_distributions(fake_site: tuple[Path, Path]) -> None:
    for group in (*groups(), "console_scripts", ENTRY_POINT_GROUP):
        same_as_importlib(group)
    names = set(ep.name for ep in scan.entry_points(group=ENTRY_POINT_GROUP))
    fake = {"fake_one", "fake_two", "fake_three", "fake_again"}
    assert "eggy" in names
    assert "shadowed" not in names
    assert fake <= names or (not fake & names and "shadowed_too" in names)


def test_the_installed_geobrep_wins_over_a_later_copy(fake_site: tuple[Path, Path]) -> None:
    impostor = [ep for ep in scan.entry_points(group=ENTRY_POINT_GROUP) if ep.name == "impostor"]
    assert impostor == []
    same_as_importlib(ENTRY_POINT_GROUP)


def test_a_geobrep_copy_first_on_sys_path_wins(
    fake_site: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """As with an ``.egg-info`` of a source checkout in the current folder."""
    monkeypatch.syspath_prepend(str(fake_site[1]))
    same_as_importlib(ENTRY_POINT_GROUP)
    names = [ep.name for ep in scan.entry_points(group=ENTRY_POINT_GROUP)]
    assert "impostor" in names
    assert "gocad" not in names


@pytest.mark.parametrize(
    "header",
    [
        "Name: odd\nVersion: 1\n",
        "Version: 1\nName: odd\nName: second\n",
        "Name:odd\nVersion:\t1 \n",
        "Name: odd\r\nVersion: 1\r\n",  # carriage returns: the email parser decides
        "From someone\nName: odd\nVersion: 1\n",
        "Name: odd\n  continued\nVersion: 1\n",
        " leading continuation\nName: odd\nVersion: 1\n",
        "Name: odd\nnot a header line\nVersion: 1\n",
        "Version: 1\n",  # no name
        "",  # no text at all
        "\nName: odd\nVersion: 1\n",
        "Name : odd\nVersion: 1\n",
        "Name: odd\nVersion: 1\n\nVersion: 2\n",
        "Name: ünï\nVersion: 1\n",
    ],
)
def test_names_and_versions_as_the_email_parser_gives_them(tmp_path: Path, header: str) -> None:
    path = dist_info(tmp_path, "odd-1.dist-info", None, "")
    (path / "METADATA").write_bytes(header.encode())
    with warnings.catch_warnings(record=True) as expected_warnings:
        warnings.simplefilter("always")
        expected = metadata.PathDistribution(path)
        expected_fields = (expected.name, expected.version)
    with warnings.catch_warnings(record=True) as our_warnings:
        warnings.simplefilter("always")
        ours = scan.Distribution(str(path))
        assert (ours.name, ours.version) == expected_fields
    assert [w.category for w in our_warnings] == [w.category for w in expected_warnings]


@pytest.mark.parametrize(
    ("stem", "text"),
    [
        ("Mixed-1.0.DIST-INFO", "[geobrep.plugins]\nmixed = geobrep_fake_good\n"),
        ("-1.0.dist-info", "[geobrep.plugins]\nnameless = geobrep_fake_good\n"),
        ("broken-1.0.dist-info", "[geobrep.plugins]\nno equals sign\n"),
        ("latin-1.0.dist-info", "[geobrep.plugins]\nbad = caf\xe9\n"),
    ],
)
def test_what_the_scan_leaves_to_importlib_metadata(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, stem: str, text: str
) -> None:
    path = dist_info(tmp_path, stem, None, f"Name: {stem.split('-')[0] or 'x'}\nVersion: 1\n")
    (path / "entry_points.txt").write_bytes(text.encode("latin-1"))
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(scan._UnsettledError):
        scan._scan(ENTRY_POINT_GROUP)
    try:
        expected: Any = described(metadata.entry_points(group=ENTRY_POINT_GROUP))
    except Exception as exc:
        expected = type(exc)
    try:
        ours: Any = described(scan.entry_points(group=ENTRY_POINT_GROUP))
    except Exception as exc:
        ours = type(exc)
    assert ours == expected


def test_a_zip_on_sys_path_is_left_to_importlib_metadata(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    archive = tmp_path / "plugins.zip"
    with zipfile.ZipFile(archive, "w") as zipped:
        zipped.writestr("zipped-1.0.dist-info/METADATA", "Name: zipped\nVersion: 1.0\n")
        zipped.writestr(
            "zipped-1.0.dist-info/entry_points.txt", "[geobrep.plugins]\nzipped = geobrep_x\n"
        )
    monkeypatch.syspath_prepend(str(archive))
    with pytest.raises(scan._UnsettledError):
        scan._scan(ENTRY_POINT_GROUP)
    same_as_importlib(ENTRY_POINT_GROUP, fast=False)
    assert "zipped" in [ep.name for ep in scan.entry_points(group=ENTRY_POINT_GROUP)]


def test_another_distribution_finder_is_left_to_importlib_metadata(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    class Finder:
        @staticmethod
        def find_spec(*args: object) -> None:
            return None

        @staticmethod
        def find_distributions(*args: object, **kwargs: object) -> list[object]:
            return []

    monkeypatch.setattr(sys, "meta_path", [*sys.meta_path, Finder])
    with pytest.raises(scan._UnsettledError):
        scan._scan(ENTRY_POINT_GROUP)
    same_as_importlib(ENTRY_POINT_GROUP, fast=False)


def test_the_importlib_metadata_backport_s_finder_is_left_to_importlib_metadata(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The backport puts its finder on ``sys.meta_path`` when imported (a test run imports it
    through other packages): the scan defers, and the loader still finds the built-ins."""
    backport = pytest.importorskip("importlib_metadata")
    finder = backport.MetadataPathFinder
    monkeypatch.setattr(sys, "meta_path", [*sys.meta_path, finder])
    with pytest.raises(scan._UnsettledError):
        scan._scan(ENTRY_POINT_GROUP)
    same_as_importlib(ENTRY_POINT_GROUP, fast=False)
    eps = discover_entry_points()
    assert {ep.name for ep in eps} >= {"native", "gocad", "clip", "blocks"}
    assert all(scan.distribution(ep)[0] == "geobrep" for ep in eps if scan.is_builtin(ep))


def test_entry_point_load_and_module_as_importlib_metadata() -> None:
    ours = scan.EntryPoint("x", "os.path : join [extra]", "g", None)
    theirs = metadata.EntryPoint("x", "os.path : join [extra]", "g")
    assert (ours.module, ours.attr, ours.load()) == (theirs.module, theirs.attr, theirs.load())
    bad, theirs_bad = (
        scan.EntryPoint("x", "not a value!", "g", None),
        metadata.EntryPoint("x", "not a value!", "g"),
    )
    with pytest.raises(AttributeError):
        theirs_bad.module  # noqa: B018
    with pytest.raises(AttributeError):
        bad.module  # noqa: B018


def test_the_scan_imports_neither_importlib_metadata_nor_email() -> None:
    code = (
        "import sys\n"
        "from geobrep.host._entry_points import entry_points, distribution\n"
        "eps = entry_points(group='geobrep.plugins')\n"
        "names = {distribution(ep) for ep in eps}\n"
        "print(sorted(names), [m for m in sys.modules if m.startswith(('importlib.metadata',"
        " 'email'))])\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd="/"
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().endswith("[]"), done.stdout
    assert "('geobrep', '0.1.0')" in done.stdout
