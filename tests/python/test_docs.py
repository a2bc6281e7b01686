"""The documents hold together: every citation of the specification ("SPEC §N", "SPEC section
N") in code, scripts and documents names a section docs/SPEC.md has, and every relative link in
the repository's Markdown points at a file that exists (and, with an anchor, at a heading it
has)."""

import pathlib
import re

from conftest import ROOT, default_config, rust_constant

SKIP_DIRS = {".git", "target", ".venv", ".venv-blender", "node_modules", "out", "__pycache__"}
SOURCE_SUFFIXES = {".rs", ".py", ".sh", ".md", ".yaml", ".toml", ".cs", ".c", ".h", ".mjs"}
CITATION = re.compile(r"SPEC\s*(?:§|section\s+)(\d+)")


def repository_files(suffixes):
    for path in ROOT.rglob("*"):
        if path.suffix in suffixes and path.is_file() and not (SKIP_DIRS & set(path.relative_to(ROOT).parts)):
            yield path


def spec_sections():
    text = (ROOT / "docs" / "SPEC.md").read_text()
    return {int(n) for n in re.findall(r"^## (\d+)\. ", text, flags=re.MULTILINE)}


def test_every_spec_citation_names_a_section_that_exists():
    sections = spec_sections()
    assert sections == set(range(1, max(sections) + 1)), sections
    cited, missing = 0, []
    for path in repository_files(SOURCE_SUFFIXES):
        for line_number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            for number in CITATION.findall(line):
                cited += 1
                if int(number) not in sections:
                    missing.append(f"{path.relative_to(ROOT)}:{line_number}: SPEC {number}")
    assert cited >= 40, f"only {cited} citations found: is the pattern still right?"
    assert not missing, "citations of sections docs/SPEC.md does not have:\n" + "\n".join(missing)


def anchors(markdown):
    """GitHub's anchors of a document's headings: lower case, punctuation dropped, spaces to '-'."""
    out = set()
    for heading in re.findall(r"^#+\s+(.*)$", markdown, flags=re.MULTILINE):
        slug = re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")
        out.add(slug)
    return out


def test_every_relative_markdown_link_points_at_something_that_exists():
    broken = []
    checked = 0
    for path in repository_files({".md"}):
        if "licenses" in path.relative_to(ROOT).parts:
            continue  # third parties' texts, kept as they wrote them
        text = path.read_text()
        # Links outside fenced code blocks.
        text = re.sub(r"```.*?```", "", text, flags=re.DOTALL)
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"^[a-z]+:", target):
                continue
            file_part, _, anchor = target.partition("#")
            linked = path if file_part == "" else (path.parent / file_part).resolve()
            checked += 1
            if not linked.exists():
                broken.append(f"{path.relative_to(ROOT)}: {target}")
            elif anchor and linked.suffix == ".md" and anchor not in anchors(linked.read_text()):
                broken.append(f"{path.relative_to(ROOT)}: {target} (no such heading)")
    assert checked >= 30, checked
    assert not broken, "broken links:\n" + "\n".join(broken)


def test_the_documents_state_the_rule_s_step_counts_as_the_code_has_them():
    """The step counts the rule chooses live in the code (clip_rule's MANY_FEET_STEPS) and the
    default configuration; the documents that explain the rule restate them for readers, so a
    change there fails here until they say the new number."""
    many_feet = rust_constant("MANY_FEET_STEPS")
    default = default_config("training", "steps")
    spaced = lambda n: f"{n:,}".replace(",", " ")  # noqa: E731 (the documents' thousands)
    for name in ("docs/GUIDE.md", "docs/SPEC.md", "configs/default.yaml"):
        text = (ROOT / name).read_text()
        for steps in (many_feet, default):
            assert f"{spaced(steps)} steps" in text, f"{name} does not state {spaced(steps)} steps"
    assert f"{spaced(many_feet)} steps" in (ROOT / "docs" / "ARCHITECTURE.md").read_text()
