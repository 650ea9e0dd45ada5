"""Every reference in the code and the docs resolves inside the repository: no citation of files that are not
in it (the shared facts sheets, the product specification, paths of a development machine), and every
``docs/<page>.md#anchor`` the code cites names a heading that exists on that page; the README stays short and
every link in it resolves."""

from __future__ import annotations

import re
import unicodedata
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
TEXT_SUFFIXES = {".py", ".yaml", ".yml", ".xml", ".md", ".json", ".txt", ".toml", ".cfg"}
SKIP_DIRS = {"__pycache__", ".venv", "site", ".cache"}

OUTSIDE = {
    "a facts sheet": re.compile(
        r"\bfacts\s*(§|/|`|\w+\.md)"
        r"|\b(original_implementation|baxter_left_arm|upper_limb_arm26|luque2011_capolei2020|dependency_stack_notes)"
        r"\.md\b"),
    "the product specification": re.compile(r"\bSPEC\b|\bSPEC\.md\b"),
    "a path of a development machine": re.compile(
        r"/work/|/home/|/Users/|(?<![\w.])/tmp/|\.\./shared\b|\bshared/(facts|seeds)\b"),
}
CITATION = re.compile(r"\bdocs/((?:[\w-]+/)*[\w-]+\.md)(?:#([\w-]+))?")
ANCHORED_PAGES = {"models.md", "provenance.md"}  # reference pages: the code cites one of their sections
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*$")
EXPLICIT_ID = re.compile(r"\{\s*#([\w-]+)[^}]*\}\s*$")


def _files(*tops: str) -> list[Path]:
    out = []
    for top in tops:
        path = ROOT / top
        if path.is_file():
            out.append(path)
            continue
        for f in sorted(path.rglob("*")):
            rel = f.relative_to(ROOT).parts
            if f.is_file() and f.suffix in TEXT_SUFFIXES and not any(
                    p in SKIP_DIRS or p.endswith(".egg-info") for p in rel):
                out.append(f)
    return out


def _lines(f: Path):
    name = f.relative_to(ROOT) if f.is_relative_to(ROOT) else f
    for no, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1):
        yield f"{name}:{no}", line


def slug(text: str) -> str:
    """MkDocs' default heading id (Python-Markdown's toc slugify) of a heading's visible text."""
    text = re.sub(r"`([^`]*)`", r"\1", text)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[*_]{1,2}([^*_]+)[*_]{1,2}", r"\1", text)
    text = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode("ascii")
    text = re.sub(r"[^\w\s-]", "", text).strip().lower()
    return re.sub(r"[-\s]+", "-", text)


def anchors(page: Path) -> set[str]:
    """Heading ids of a page: explicit ``{#id}`` attributes, else the slug of the heading text."""
    out, fenced = set(), False
    for line in page.read_text(encoding="utf-8").splitlines():
        if line.lstrip().startswith(("```", "~~~")):
            fenced = not fenced
        m = None if fenced else HEADING.match(line)
        if m:
            explicit = EXPLICIT_ID.search(m.group(1))
            out.add(explicit.group(1) if explicit else slug(m.group(1)))
    return out


def outside_citations(files: list[Path], pattern: re.Pattern) -> list[str]:
    """``file:line: text`` of every line that matches ``pattern``."""
    return [f"{where}: {line.strip()[:100]}" for f in files for where, line in _lines(f) if pattern.search(line)]


def citation_problems(files: list[Path], docs: Path = DOCS) -> list[str]:
    """Citations of ``docs/<page>.md[#anchor]`` whose page or heading does not exist, or that cite a reference
    page without a section from code or configuration."""
    cache: dict[str, set[str] | None] = {}
    problems = []
    for f in files:
        for where, line in _lines(f):
            for page, anchor in CITATION.findall(line):
                if page not in cache:
                    path = docs / page
                    cache[page] = anchors(path) if path.is_file() else None
                if cache[page] is None:
                    problems.append(f"{where}: docs/{page} does not exist")
                elif anchor and anchor not in cache[page]:
                    problems.append(f"{where}: docs/{page} has no heading #{anchor}")
                elif not anchor and page in ANCHORED_PAGES and f.suffix != ".md":  # a page may link a whole page
                    problems.append(f"{where}: docs/{page} cited without a section (#anchor)")
    return problems


def test_slug_is_mkdocs_default():
    assert slug("Joint limits") == "joint-limits"
    assert slug("`future_past`: mean of future and past samples, with a safe stop") == (
        "future_past-mean-of-future-and-past-samples-with-a-safe-stop")
    assert slug("Springs, SEAs & gravity compensation") == "springs-seas-gravity-compensation"


@pytest.mark.parametrize("what", sorted(OUTSIDE))
def test_nothing_cites_files_outside_the_repository(what):
    hits = outside_citations(_files("src", "conf", "docs", "README.md"), OUTSIDE[what])
    assert not hits, f"{len(hits)} citation(s) of {what}; cite a section of the docs instead:\n" + "\n".join(hits)


def test_every_cited_docs_anchor_exists():
    files = [f for f in _files("src", "conf", "tests", "README.md") if f != Path(__file__).resolve()]
    problems = citation_problems(files)
    assert not problems, "\n".join(problems)


def test_the_code_cites_the_reference_pages():
    """The check above has something to check: the code points at sections of both reference pages."""
    cited = {page for f in _files("src", "conf") for _, line in _lines(f) for page, _ in CITATION.findall(line)}
    assert ANCHORED_PAGES <= cited


MD_LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
README_MAX_LINES = 150


def link_problems(page: Path, root: Path = ROOT) -> list[str]:
    """Relative links of a Markdown file whose target (file or folder, and heading if one is named) does not
    exist; web links are not followed."""
    problems = []
    for where, line in _lines(page):
        for target in MD_LINK.findall(line):
            if re.match(r"[a-z]+:", target) or target.startswith("#"):
                continue
            path, _, anchor = target.partition("#")
            dest = (page.parent / path).resolve()
            if not dest.exists() or not dest.is_relative_to(root):
                problems.append(f"{where}: {target} does not exist in the repository")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                problems.append(f"{where}: {path} has no heading #{anchor}")
    return problems


def test_the_readme_is_short_and_its_links_resolve():
    readme = ROOT / "README.md"
    assert len(readme.read_text(encoding="utf-8").splitlines()) <= README_MAX_LINES
    assert link_problems(readme) == []


def test_planted_bad_references_are_caught(tmp_path):
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "models.md").write_text("# Models\n\n## Kernel STDP {#kernel-stdp}\n\n### Joint limits\n")
    code = tmp_path / "code.py"
    code.write_text('"""See docs/models.md#kernel-stdp and docs/models.md#joint-limits."""\n'
                    "# docs/models.md#no-such-section, docs/models.md, docs/nowhere.md\n"
                    "# numbers from facts §3, facts/baxter_left_arm.md and SPEC §2, at /work/shared/facts/x.md\n")
    problems = citation_problems([code], docs)
    assert [p.split(": ", 1)[1] for p in problems] == [
        "docs/models.md has no heading #no-such-section", "docs/models.md cited without a section (#anchor)",
        "docs/nowhere.md does not exist"]
    for what, pattern in OUTSIDE.items():
        assert outside_citations([code], pattern), what
    readme = tmp_path / "README.md"
    readme.write_text("[ok](docs/models.md#kernel-stdp) [web](https://x.org) ![no](docs/fig.png) "
                      "[bad](docs/models.md#nowhere) [up](../outside.md)\n")
    assert [p.split(": ", 1)[1] for p in link_problems(readme, tmp_path)] == [
        "docs/fig.png does not exist in the repository", "docs/models.md has no heading #nowhere",
        "../outside.md does not exist in the repository"]
    code.write_text("# artefacts and the facts of life; a spec; docs/models.md#kernel-stdp\n")
    assert not citation_problems([code], docs)
    assert not any(outside_citations([code], pattern) for pattern in OUTSIDE.values())
