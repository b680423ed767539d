"""A real editor: Neovim headless (Debian's ``neovim``) with its built-in LSP client runs
``urdftool lsp`` on a seed xacro, reads back the diagnostics at the xacro lines, applies a quick
fix through its own ``apply_workspace_edit`` and sees the diagnostic go."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import pytest

from tests.conftest import ROBOTS, ROOT
from tests.lsp_client import check_json

NVIM = shutil.which("nvim")
pytestmark = pytest.mark.skipif(
    NVIM is None, reason="Neovim is not installed (apt-get install neovim; .ci/run installs it "
                         "where apt-get can)")

SCRIPT = r"""
local out, file, python, root = _G.arg_out, _G.arg_file, _G.arg_python, _G.arg_root
local result = {}
vim.cmd('edit ' .. vim.fn.fnameescape(file))
local buf = vim.api.nvim_get_current_buf()
local id = vim.lsp.start_client({
  cmd = {python, '-m', 'urdftool', 'lsp'},
  cmd_env = {PYTHONPATH = root},
  root_dir = vim.fn.fnamemodify(file, ':h'),
  init_options = {trusted = true},
})
vim.lsp.buf_attach_client(buf, id)
local function rules()
  local found = {}
  for _, d in ipairs(vim.diagnostic.get(buf)) do
    local code = d.code or (d.user_data and d.user_data.lsp and d.user_data.lsp.code)
    table.insert(found, {line = d.lnum + 1, col = d.col + 1, code = code,
                         severity = d.severity})
  end
  return found
end
result.ready = vim.wait(60000, function() return #vim.diagnostic.get(buf) > 0 end, 50)
result.before = rules()
local client = vim.lsp.get_client_by_id(id)
-- the quick fix of the first xml.unclosed-tag, asked for as the editor asks
local target
for _, d in ipairs(result.before) do
  if d.code == 'xml.unclosed-tag' and (target == nil or d.line < target.line) then target = d end
end
result.target = target
local params = {
  textDocument = {uri = vim.uri_from_bufnr(buf)},
  range = {start = {line = target.line - 1, character = 0},
           ['end'] = {line = target.line - 1, character = 0}},
  context = {diagnostics = {}, only = {'quickfix'}},
}
local response = client.request_sync('textDocument/codeAction', params, 20000, buf)
result.titles = {}
local chosen
for _, action in ipairs(response.result or {}) do
  table.insert(result.titles, action.title)
  if chosen == nil and action.isPreferred then chosen = action end
end
result.chosen = chosen and chosen.title
vim.lsp.util.apply_workspace_edit(chosen.edit, client.offset_encoding or 'utf-16')
result.fixed_line = vim.api.nvim_buf_get_lines(buf, target.line - 1, target.line, false)[1]
local before = #result.before
result.updated = vim.wait(60000, function() return #vim.diagnostic.get(buf) < before end, 50)
result.after = rules()
vim.fn.writefile({vim.fn.json_encode(result)}, out)
client.stop()
vim.wait(5000, function() return client.is_stopped() end, 50)
vim.cmd('qa!')
"""


def test_neovim_shows_the_findings_at_the_xacro_lines_and_applies_a_fix(tmp_path):
    package = tmp_path / "m2wr"
    shutil.copytree(ROBOTS / "m2wr" / "published", package)
    robot = package / "m2wr.xacro"
    script = tmp_path / "drive.lua"
    out = tmp_path / "result.json"
    script.write_text(SCRIPT, encoding="utf-8")
    setup = (f"lua _G.arg_out={json.dumps(str(out))}; _G.arg_file={json.dumps(str(robot))}; "
             f"_G.arg_python={json.dumps(sys.executable)}; _G.arg_root={json.dumps(str(ROOT))}")
    done = subprocess.run([NVIM, "--headless", "--clean", "-n", "-c", setup,
                           "-c", f"luafile {script}"], capture_output=True, text=True,
                          timeout=180, cwd=tmp_path, check=False)
    assert out.is_file(), done.stderr + done.stdout
    result = json.loads(out.read_text(encoding="utf-8"))
    assert result["ready"], result
    expected = {(rule, line, column) for rule, path, line, column, _ in check_json(
        "--trusted", str(package)) if path == str(robot.resolve())}
    assert {(d["code"], d["line"], d["col"]) for d in result["before"]} == expected
    target = result["target"]
    assert result["chosen"].startswith("Fix xml.unclosed-tag")
    text = robot.read_text(encoding="utf-8").split("\n")
    assert "</" in result["fixed_line"] and result["fixed_line"] != text[target["line"] - 1]
    assert result["updated"], result
    after = {(d["code"], d["line"]) for d in result["after"]}
    assert ("xml.unclosed-tag", target["line"]) not in after
    assert len(result["after"]) == len(result["before"]) - 1


README_DRIVER = r"""
local out, file = _G.arg_out, _G.arg_file
vim.cmd('edit ' .. vim.fn.fnameescape(file))
local buf = vim.api.nvim_get_current_buf()
local ready = vim.wait(60000, function() return #vim.diagnostic.get(buf) > 0 end, 50)
local found = {}
for _, d in ipairs(vim.diagnostic.get(buf)) do
  local code = d.code or (d.user_data and d.user_data.lsp and d.user_data.lsp.code)
  table.insert(found, {line = d.lnum + 1, col = d.col + 1, code = code})
end
vim.fn.writefile({vim.fn.json_encode({ready = ready, filetype = vim.bo[buf].filetype,
                                      found = found})}, out)
for _, client in pairs(vim.lsp.get_active_clients()) do client.stop() end
vim.wait(5000, function() return #vim.lsp.get_active_clients() == 0 end, 50)
vim.cmd('qa!')
"""


def test_the_readmes_neovim_07_configuration_works_as_written(tmp_path):
    """The README's configuration for Neovim 0.7, copied from the README unchanged, as a user's
    init.lua: opening a seed xacro shows the findings `check` gives, at their lines."""
    import os
    import re

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    config = re.search(r"Neovim 0\.7 \(Debian[^\n]*\n\n```lua\n(.*?)```", readme, re.DOTALL)
    assert config, "the README has no Neovim 0.7 configuration"
    package = tmp_path / "m2wr"
    shutil.copytree(ROBOTS / "m2wr" / "published", package)
    robot = package / "m2wr.xacro"
    (tmp_path / "init.lua").write_text(config.group(1), encoding="utf-8")
    (tmp_path / "drive.lua").write_text(README_DRIVER, encoding="utf-8")
    out = tmp_path / "result.json"
    setup = f"lua _G.arg_out={json.dumps(str(out))}; _G.arg_file={json.dumps(str(robot))}"
    # `urdftool` found on PATH, as the README assumes: this interpreter's, reading this tree
    env = {**os.environ, "PATH": os.path.dirname(sys.executable) + os.pathsep
           + os.environ.get("PATH", ""), "PYTHONPATH": str(ROOT),
           "XDG_CONFIG_HOME": str(tmp_path / "config"), "XDG_DATA_HOME": str(tmp_path / "data"),
           "XDG_STATE_HOME": str(tmp_path / "state")}
    init = str(tmp_path / "init.lua")
    done = subprocess.run([NVIM, "--headless", "-n", "-i", "NONE", "-u", init,
                           "-c", setup, "-c", f"luafile {tmp_path / 'drive.lua'}"],
                          capture_output=True, text=True, timeout=180, cwd=package, env=env,
                          check=False)
    assert out.is_file(), done.stderr + done.stdout
    result = json.loads(out.read_text(encoding="utf-8"))
    assert result["ready"] and result["filetype"] == "xml", result
    expected = {(rule, line, column) for rule, path, line, column, _ in check_json(
        "--trusted", str(package)) if path == str(robot.resolve())}
    assert {(d["code"], d["line"], d["col"]) for d in result["found"]} == expected
