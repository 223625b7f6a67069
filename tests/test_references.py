"""The published relations the code uses and :data:`craters.REFERENCES` agree (issue 31).

A citation is an author-year form in the source of the three packages: ``Pike 1977``,
``Pike (1977)``, ``Fassett & Thomson 2014``, ``Martin, Parkes & Dunstan 2014``,
``Li et al. (2022``, ``Wyvill, McPheeters & Wyvill's (1986)``, ``Thomas et al. 1994,
1996``, also across the lines of a comment or of implicitly joined strings. It resolves
to an entry by the first author's surname and the year; a citation naming every author
(no "et al.") must match the entry's author list exactly, one with "et al." an entry of
more than two authors. Every entry must be cited; entries that share a surname and a
year must each be told apart somewhere (a citation that resolves to it alone, or its
title in the source). Non-authors before a year (``Bulk 1900 kg/m^3``, ``CODATA 2018``)
and the one mention that is not a publication are listed below with the reason.
"""

from __future__ import annotations

import re
import unicodedata
from collections import defaultdict
from pathlib import Path

import pytest

import craters
from craters.references import REFERENCES, Reference

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("craters", "latlong", "dem")

#: Capitalised words that stand before a year without being an author.
NOT_AUTHORS = ("Bulk", "CODATA", "IAU", "Mars", "Mercury", "Moon")
#: (surname, year) mentions that are not publications, with the reason.
NOT_PUBLICATIONS = {
    ("kinch", 2017): "a correction by K. Kinch (2017-03) recorded in craterstats' "
                     "functions.txt, quoted with Hartmann (1984); not a publication",
}

_NAME = (rf"(?:(?:van|von|de|della|le) )?(?!(?:{'|'.join(NOT_AUTHORS)})\b)"
         r"[A-Z][^\W\d_]*(?:[-'][A-Z][^\W\d_]*)*")
_YEAR = r"(?:1[6-9]|20)\d\d"
CITATION = re.compile(
    rf"(?<![\w.])(?P<first>{_NAME})"
    rf"(?P<rest>(?:, {_NAME})*,? (?:&|and) {_NAME}| et al\.?)?"
    rf"(?:'s)?,? \(?(?P<years>{_YEAR}[a-z]?(?:(?:, ?|/| and ){_YEAR}[a-z]?)*)(?!\d)")
_COAUTHOR = re.compile(rf"(?:, |,? (?:&|and) )({_NAME})")


def fold(name: str) -> str:
    """A surname compared without case or accents (ö as oe, æ as ae: Schröder = Schroeder)."""
    name = name.lower()
    for a, b in (("ä", "ae"), ("ö", "oe"), ("ü", "ue"), ("æ", "ae"), ("ø", "oe"), ("ß", "ss")):
        name = name.replace(a, b)
    return "".join(c for c in unicodedata.normalize("NFKD", name)
                   if not unicodedata.combining(c))


def one_line(text: str) -> str:
    """Source text as one line: implicitly joined strings and comment continuations closed."""
    text = re.sub(r"[\"']\s*\n\s*[rbfu]*[\"']", "", text)
    return re.sub(r"\s*\n\s*(?:#:?\s*)?", " ", text)


def source_text(path: Path) -> str:
    return one_line(path.read_text(encoding="utf-8"))


def source_files() -> list[Path]:
    """The packages' Python and Markdown files, but the list of references itself."""
    return [p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*"))
            if p.suffix in (".py", ".md") and "__pycache__" not in p.parts
            and p != ROOT / "craters" / "references.py"]


def citations(text: str):
    """(surname, co-authors or None, et al., [years], matched text) of each citation."""
    for m in CITATION.finditer(text):
        rest = m.group("rest") or ""
        etal = rest.startswith(" et al")
        coauthors = None if etal or not rest else _COAUTHOR.findall(rest)
        years = [int(y[:4]) for y in re.findall(_YEAR + "[a-z]?", m.group("years"))]
        yield m.group("first"), coauthors, etal, years, m.group(0)


def candidates(first: str, coauthors, etal: bool, year: int) -> list[Reference]:
    """The entries a citation of ``year`` can mean."""
    out = []
    for ref in REFERENCES.values():
        names = [fold(s) for s in ref.surnames]
        if names[0] != fold(first) or ref.year != year:
            continue
        if coauthors is not None and ("et al." in ref.authors
                                      or names != [fold(first)] + [fold(c) for c in coauthors]):
            continue
        if etal and len(names) <= 2 and "et al." not in ref.authors:
            continue
        out.append(ref)
    if not out and "-" in first and coauthors is None:  # craterstats' "Neukum-Ivanov (2001)"
        parts = [candidates(part, None, False, year) for part in first.split("-")]
        if all(parts):
            out = [ref for part in parts for ref in part]
    return out


@pytest.fixture(scope="module")
def found():
    """Every citation in the packages: (file, text, surname, year, candidates)."""
    rows = []
    for path in source_files():
        for first, coauthors, etal, years, text in citations(source_text(path)):
            for year in years:
                rows.append((path.relative_to(ROOT).as_posix(), text, first, year,
                             candidates(first, coauthors, etal, year)))
    return rows


def test_the_parser_reads_the_citation_forms():
    text = ("after Pike 1977 and Pike (1977), Fassett & Thomson (2014, JGR), Li et al. (2022, "
            "A&A), Martin, Parkes & Dunstan 2014, Wyvill, McPheeters & Wyvill's (1986) kernel, "
            "Thomas et al. 1994, 1996, Lunar equilibrium (Trask, 1966), Bulk 1900 kg/m^3")
    got = [(first, coauthors, etal, years) for first, coauthors, etal, years, _ in
           citations(text)]
    assert got == [("Pike", None, False, [1977]), ("Pike", None, False, [1977]),
                   ("Fassett", ["Thomson"], False, [2014]), ("Li", None, True, [2022]),
                   ("Martin", ["Parkes", "Dunstan"], False, [2014]),
                   ("Wyvill", ["McPheeters", "Wyvill"], False, [1986]),
                   ("Thomas", None, True, [1994, 1996]), ("Trask", None, False, [1966])]
    joined = one_line('x = ("(Michel et "\n     "al. 2009 Icarus)")\n#: (Park et\n#: al. 2016)')
    assert [c[0] for c in citations(joined)] == ["Michel", "Park"]


def test_the_packages_cite_many_works(found):
    # guards the test below against a pattern that silently stops matching
    assert len(found) > 250
    assert len({ref.key for *_, cands in found for ref in cands}) > 80


def test_every_citation_resolves_to_an_entry(found):
    unresolved = sorted({f"{path}: {text!r} ({year})" for path, text, first, year, cands
                         in found if not cands and (fold(first), year) not in NOT_PUBLICATIONS})
    assert not unresolved, "citations without an entry in craters.REFERENCES:\n" + \
        "\n".join(unresolved)


def test_every_entry_is_cited_and_told_apart(found):
    cited = {ref.key for *_, cands in found for ref in cands}
    assert not set(REFERENCES) - cited, f"entries never cited: {sorted(set(REFERENCES) - cited)}"
    alone = {cands[0].key for *_, cands in found if len(cands) == 1}
    text = " ".join(fold(source_text(p)) for p in source_files())
    text = re.sub(r"\s+", " ", text)
    groups = defaultdict(list)
    for ref in REFERENCES.values():
        groups[fold(ref.surnames[0]), ref.year].append(ref)
    vague = [ref.key for refs in groups.values() if len(refs) > 1 for ref in refs
             if ref.key not in alone and re.sub(r"\s+", " ", fold(ref.title)) not in text]
    assert not vague, f"entries sharing author and year that no citation tells apart: {vague}"


def test_entries_are_well_formed():
    dois = [r.doi for r in REFERENCES.values() if r.doi is not None]
    assert len(dois) == len(set(dois))
    for key, ref in REFERENCES.items():
        assert ref.key == key
        assert re.fullmatch(rf"[a-z]+{ref.year}[a-z]*", key), key
        assert ref.doi is None or re.fullmatch(r"10\.[0-9]{4,9}/[^\s]+[^\s.,;)]", ref.doi), key
        assert ref.title and ref.venue, key
        assert all(re.fullmatch(r"[^\W\d_][^,]*, [^\W\d_].*|et al\.", a) for a in ref.authors), key
        assert "et al." not in ref.authors[:-1], key


def test_reference_lookup():
    assert craters.reference("fassett2014") is REFERENCES["fassett2014"]
    assert craters.reference("fassett2014").cite() == "Fassett & Thomson 2014"
    assert craters.reference("neukum2001").cite() == "Neukum et al. 2001"
    assert "doi:10.1002/2014JE004698" in str(craters.reference("fassett2014"))
    with pytest.raises(ValueError, match=r"`key` must be a key of craters.REFERENCES; got "
                       r"'fasset2014' \(did you mean fassett2014"):
        craters.reference("fasset2014")


@pytest.mark.parametrize(("field", "value", "message"), [
    ("key", "Pike1977", "`key` must be surname"),
    ("authors", (), "`authors` must be non-empty"),
    ("year", 77, r"`year` must be in \[1600, 2100\]"),
    ("doi", "doi:10.1002/x", "`doi` must look like 10.NNNN/"),
])
def test_reference_checks_its_fields(field, value, message):
    fields = {"key": "pike1977", "authors": ("Pike, R. J.",), "year": 1977, "title": "t",
              "venue": "v", "doi": None, field: value}
    with pytest.raises(ValueError, match=message):
        Reference(**fields)
