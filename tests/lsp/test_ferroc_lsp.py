"""End-to-end tests of `ferroc lsp` with pytest-lsp (a client we did not write).

Run by tests/lsp_clients.rs with FERROC (the binary) and FERROC_ROOT (the checkout)
set: initialize, open, diagnostics, change, definition, hover, completion, code
action (applied and re-checked clean), document symbols and shutdown.
"""

import json
import os
import pathlib
import shutil
import subprocess
import sys

import pytest
import pytest_lsp
from lsprotocol import types
from pytest_lsp import ClientServerConfig, LanguageClient

FERROC = os.environ["FERROC"]
ROOT = pathlib.Path(os.environ["FERROC_ROOT"]).resolve()
SCRATCH = pathlib.Path(os.environ["FERROC_SCRATCH"]).resolve()
MODEL = ROOT / "models" / "crash_course.xml"
MANIFEST = ROOT / "components" / "crash_course.lib.xml"


@pytest_lsp.fixture(config=ClientServerConfig(server_command=[FERROC, "lsp"]))
async def client(lsp_client: LanguageClient):
    params = types.InitializeParams(
        capabilities=types.ClientCapabilities(),
        root_uri=SCRATCH.as_uri(),
    )
    await lsp_client.initialize_session(params)
    yield
    await lsp_client.shutdown_session()


def scratch_model(name: str, text: str) -> pathlib.Path:
    """A copy of the example models (with the crash-course manifest where the models
    look for it) and `text` as `name` beside them."""
    models = SCRATCH / "models"
    if not models.exists():
        shutil.copytree(ROOT / "models", models)
        (SCRATCH / "components").mkdir(exist_ok=True)
        shutil.copy(MANIFEST, SCRATCH / "components" / MANIFEST.name)
    path = models / name
    path.write_text(text)
    return path


def summary(diagnostics) -> list:
    """(code, line, column, severity) of LSP diagnostics, 1-based as ferroc check says."""
    return sorted((d.code, d.range.start.line + 1, d.range.start.character + 1, d.severity.value) for d in diagnostics)


def cli_summary(path: pathlib.Path) -> list:
    sev = {"error": 1, "warning": 2, "note": 3}
    return sorted(
        (d["code"], d["primary"]["location"]["line"], d["primary"]["location"]["column"], sev[d["severity"]])
        for d in check_json(path)
        if pathlib.Path(ROOT / d["primary"]["location"]["file"]).resolve() == path.resolve()
        or pathlib.Path(d["primary"]["location"]["file"]).resolve() == path.resolve()
    )


def position_of(text: str, needle: str, into: int = 0) -> types.Position:
    offset = text.index(needle) + into
    line = text.count("\n", 0, offset)
    column = offset - (text.rfind("\n", 0, offset) + 1)
    return types.Position(line=line, character=column)


def check_json(path: pathlib.Path) -> list:
    out = subprocess.run(
        [FERROC, "check", "--format", "json", str(path)],
        capture_output=True, text=True, cwd=ROOT, check=False,
    )
    return json.loads(out.stdout)["models"][0]["diagnostics"]


async def open_and_settle(client: LanguageClient, path: pathlib.Path, text: str, version: int = 1):
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            text_document=types.TextDocumentItem(
                uri=path.as_uri(), language_id="xml", version=version, text=text
            )
        )
    )
    await settle(client, path)


async def settle(client: LanguageClient, path: pathlib.Path):
    # A hover is answered after the check of the current text: the diagnostics of
    # that check have been published by then.
    await client.text_document_hover_async(
        types.HoverParams(
            text_document=types.TextDocumentIdentifier(uri=path.as_uri()),
            position=types.Position(line=0, character=0),
        )
    )


async def test_example_model_is_clean_and_navigation_works(client: LanguageClient):
    text = MODEL.read_text()
    await open_and_settle(client, MODEL, text)
    assert summary(client.diagnostics.get(MODEL.as_uri(), [])) == cli_summary(MODEL)
    assert not [d for d in client.diagnostics.get(MODEL.as_uri(), []) if d.severity.value == 1]

    # Go to definition from a connection end: the instance and the port's line in
    # the manifest.
    at = position_of(text, 'from="main_simulation/ir_distance_front"', len('from="main_simulation/ir_d'))
    result = await client.text_document_definition_async(
        types.DefinitionParams(
            text_document=types.TextDocumentIdentifier(uri=MODEL.as_uri()), position=at
        )
    )
    targets = {(pathlib.Path(l.uri[len("file://"):]).resolve(), l.range.start.line) for l in result}
    manifest_lines = MANIFEST.read_text().split("\n")
    port_lines = [i for i, l in enumerate(manifest_lines) if 'name="ir_distance_front"' in l]
    assert any(p == MANIFEST.resolve() and line in port_lines for p, line in targets), targets
    instance_line = text.split("\n").index(next(l for l in text.split("\n") if 'name="main_simulation"' in l))
    assert (MODEL.resolve(), instance_line) in targets, targets

    # Hover on the same end: the port's type and direction.
    hover = await client.text_document_hover_async(
        types.HoverParams(text_document=types.TextDocumentIdentifier(uri=MODEL.as_uri()), position=at)
    )
    assert "output" in hover.contents.value and "ir_distance_front" in hover.contents.value, hover

    # References of that port: every connection end that names it.
    refs = await client.text_document_references_async(
        types.ReferenceParams(
            text_document=types.TextDocumentIdentifier(uri=MODEL.as_uri()),
            position=at,
            context=types.ReferenceContext(include_declaration=False),
        )
    )
    uses = [i for i, l in enumerate(text.split("\n")) if '"main_simulation/ir_distance_front"' in l]
    assert sorted(r.range.start.line for r in refs) == uses, refs

    # Hover on a thread container's name: its period.
    at = position_of(text, '<thread name="main"', len('<thread name="'))
    hover = await client.text_document_hover_async(
        types.HoverParams(text_document=types.TextDocumentIdentifier(uri=MODEL.as_uri()), position=at)
    )
    assert "thread container" in hover.contents.value and "ms" in hover.contents.value, hover

    # Completion in from= offers the ports that exist, outputs first.
    at = position_of(text, 'from="main_simulation/ir_distance_front"', len('from="'))
    items = await client.text_document_completion_async(
        types.CompletionParams(text_document=types.TextDocumentIdentifier(uri=MODEL.as_uri()), position=at)
    )
    labels = [i.label for i in sorted(items.items, key=lambda i: i.sort_text or i.label)]
    assert "main_simulation/ir_distance_front" in labels, labels[:20]
    assert "main_simulation/velocity" in labels
    assert labels.index("main_simulation/ir_distance_front") < labels.index("main_simulation/velocity")

    # Document symbols: the element tree, by name.
    symbols = await client.text_document_document_symbol_async(
        types.DocumentSymbolParams(text_document=types.TextDocumentIdentifier(uri=MODEL.as_uri()))
    )
    names = []

    def walk(s):
        names.append(s.name)
        for c in s.children or []:
            walk(c)

    for s in symbols:
        walk(s)
    assert "main_simulation" in names and "crash_course" in names, names


async def test_broken_model_diagnostics_equal_ferroc_check_and_quick_fix_makes_it_clean(client: LanguageClient):
    clean = MODEL.read_text()
    text = clean.replace('type="crash_course.AddNoise"', 'type="crash_course.AddNoize"', 1)
    model = scratch_model("broken.xml", text)
    await open_and_settle(client, model, text)
    got = [d for d in client.diagnostics[model.as_uri()] if d.severity.value == 1]
    assert summary(client.diagnostics[model.as_uri()]) == cli_summary(model)
    assert got, "the misspelt type is an error"

    # The quick fix from "did you mean": applied as the client would, then re-checked.
    at = got[0].range
    actions = await client.text_document_code_action_async(
        types.CodeActionParams(
            text_document=types.TextDocumentIdentifier(uri=model.as_uri()),
            range=at,
            context=types.CodeActionContext(diagnostics=got),
        )
    )
    assert actions, "a quick fix is offered"
    edit = actions[0].edit.changes[model.as_uri()][0]
    lines = text.split("\n")
    line = lines[edit.range.start.line]
    lines[edit.range.start.line] = line[: edit.range.start.character] + edit.new_text + line[edit.range.end.character :]
    fixed = "\n".join(lines)
    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=model.as_uri(), version=2),
            content_changes=[types.TextDocumentContentChangeWholeDocument(text=fixed)],
        )
    )
    await settle(client, model)
    assert fixed == clean, "the fix restores the model's text, layout and comments"
    model.write_text(fixed)
    assert summary(client.diagnostics[model.as_uri()]) == cli_summary(model)
    assert not [d for d in client.diagnostics[model.as_uri()] if d.severity.value == 1]


async def test_incremental_change_breaks_and_repairs(client: LanguageClient):
    text = MODEL.read_text()
    model = scratch_model("incremental.xml", text)
    await open_and_settle(client, model, text)
    clean = summary(client.diagnostics.get(model.as_uri(), []))
    assert clean == cli_summary(model)
    start = position_of(text, 'to="add_noise_front/input"', len('to="'))
    end = types.Position(line=start.line, character=start.character + len("add_noise_front"))
    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=model.as_uri(), version=2),
            content_changes=[types.TextDocumentContentChangePartial(range=types.Range(start=start, end=end), text="add_noise_nowhere")],
        )
    )
    await settle(client, model)
    broken = summary(client.diagnostics[model.as_uri()])
    assert broken != clean, "the unknown module in to= is a finding"
    model.write_text(text.replace('to="add_noise_front/input"', 'to="add_noise_nowhere/input"', 1))
    assert broken == cli_summary(model)
    model.write_text(text)
    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=model.as_uri(), version=3),
            content_changes=[types.TextDocumentContentChangePartial(
                range=types.Range(start=start, end=types.Position(line=start.line, character=start.character + len("add_noise_nowhere"))),
                text="add_noise_front")],
        )
    )
    await settle(client, model)
    assert summary(client.diagnostics[model.as_uri()]) == clean


# Quick fixes beyond "did you mean": (fixture, code, whether the fixed file checks
# clean, the fixture's text changed first). T109's fixture gains a speedometer (the one
# output of the motor's type and unit) and a compass (the same type in radians, which
# must not be offered; its output stays unused, T110). T101's fixture swapped gives a duplicate of its other connection
# (T107), S106's has two more flows no swap mends, D115's cycle once started is a
# data-flow loop in one container (S101, the warning of the case above), and the P110,
# B103 and B108 fixtures have two findings each: there the fixed finding must go.
T109_SOURCES = (
    '<module name="motor" type="fx.Motor"/>',
    '<module name="compass" type="fx.Compass"/>\n      <module name="speedo" type="fx.Speedometer"/>\n'
    '      <module name="motor" type="fx.Motor"/>',
)
FIXES = [
    ("scheduling/s101_data_flow_loop/fires.xml", "S101", True, None),
    ("deadlocks/d107_full_queue_ring/fires.xml", "D107", True, None),
    ("deadlocks/d115_trigger_cycle_never_runs/fires.xml", "D115", False, None),
    ("connections/t109_required_input_unconnected/fires.xml", "T109", False, T109_SOURCES),
    ("connections/t112_double_scaling/fires.xml", "T112", True, None),
    ("connections/t101_wrong_direction/fires.xml", "T101", False, None),
    ("scheduling/s106_flow_not_connected/fires.xml", "S106", False, None),
    ("parameters/p110_value_without_unit/fires.xml", "P110", False, None),
    ("deployment/x103_host_label_conflict/fires.xml", "X103", True, None),
    ("behaviour/b103_never_stimulated/fires.xml", "B103", False, None),
    ("behaviour/b108_incomplete_fusion_channel/fires.xml", "B108", False, None),
    ("../../model/src/checks/l104_library_not_used/fires.xml", "L104", True, None),
]


def fixture_copy(rel: str, code: str, change) -> pathlib.Path:
    """The check fixture `rel` (below compiler/checks/src, or compiler/… when it starts
    with `../`) in the scratch folder, its manifest named absolutely."""
    source = (ROOT / "compiler" / "checks" / "src" / rel).resolve()
    text = source.read_text()
    if change:
        assert change[0] in text
        text = text.replace(change[0], change[1])
    start = text.index('manifest="') + len('manifest="') if 'manifest="' in text else -1
    if start >= 0:
        end = text.index('"', start)
        text = text[:start] + str((source.parent / text[start:end]).resolve()) + text[end:]
    folder = SCRATCH / "fixes"
    folder.mkdir(exist_ok=True)
    path = folder / f"{code.lower()}.xml"
    path.write_text(text)
    return path


def offset_of(text: str, pos: types.Position) -> int:
    lines = text.split("\n")
    return sum(len(l) + 1 for l in lines[: pos.line]) + pos.character


def apply_edits(text: str, edits) -> str:
    """The client's side of a WorkspaceEdit: the edits applied from the last to the first."""
    for e in sorted(edits, key=lambda e: (e.range.start.line, e.range.start.character), reverse=True):
        text = text[: offset_of(text, e.range.start)] + e.new_text + text[offset_of(text, e.range.end) :]
    return text


@pytest.mark.parametrize("rel,code,clean,change", FIXES)
async def test_quick_fix_applied_by_the_client_mends_the_finding(client: LanguageClient, rel, code, clean, change):
    path = fixture_copy(rel, code, change)
    text = path.read_text()
    await open_and_settle(client, path, text)
    found = [d for d in client.diagnostics[path.as_uri()] if d.code == code]
    assert found, f"the fixture reports {code}"
    actions = await client.text_document_code_action_async(
        types.CodeActionParams(
            text_document=types.TextDocumentIdentifier(uri=path.as_uri()),
            range=found[0].range,
            context=types.CodeActionContext(diagnostics=found[:1]),
        )
    )
    mine = [a for a in actions or [] if a.title.startswith(code + ":")]
    assert mine, f"a quick fix for {code}: {[a.title for a in actions or []]}"
    if code == "T109":
        assert [a.title for a in mine] == ["T109: connect `robot/main/speedo/speed` → `robot/main/motor/velocity`"]
        assert mine[0].is_preferred
    fixed = apply_edits(text, mine[0].edit.changes[path.as_uri()])
    assert fixed != text
    comments = lambda t: [l.strip() for l in t.split("\n") if l.strip().startswith("<!--")]
    assert comments(fixed) == comments(text), "comments kept"
    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=path.as_uri(), version=2),
            content_changes=[types.TextDocumentContentChangeWholeDocument(text=fixed)],
        )
    )
    await settle(client, path)
    after = client.diagnostics[path.as_uri()]
    assert len([d for d in after if d.code == code]) == len(found) - 1, (mine[0].title, summary(after))
    path.write_text(fixed)
    assert summary(after) == cli_summary(path)
    if clean:
        assert not [d for d in after if d.severity.value <= 2], (mine[0].title, summary(after))
