"""`urdftool diff` (issue 30): `compare` (two robots -> changes, analysis layer), `revisions`
(git objects -> temporary trees), `run` (which robots, both sides read as check reads them),
`formats` (JSON, text, markdown), `render` (before/after pictures)."""
