"""The recording sheet: which recordings the workflow identifies, of what kind, in which group.

A sheet is a tab-separated table (config ``recordings``, e.g. ``config/recordings.tsv``; lines
starting with ``#`` are comments) with a header and one row per recording:

========= ===============================================================================
column    meaning
========= ===============================================================================
recording name (letters, digits, ``_``, ``-``), unique over the sheets; names the files
          written for it
file      the recording: a CSV in the recording format (kind ``converted``,
          ``harvester.data.recording``), the virtual rig's raw DAQ volts (``raw_daq``: CSV
          with its JSON beside it, converted first), an EMPS .mat file (``emps``) or a
          public benchmark's .mat file read by ``harvester.data.public`` (``public``: the
          frame's ``s_b_{load}g_x.mat`` with its ``_y.mat`` beside it, the Silverbox's
          ``Schroeder80mV.mat``; its sidecar is the reader's)
kind      converted | raw_daq | emps | public
sidecar   YAML with what is known of the device (``harvester.data.sidecar``: M, m, k,
          priors, filtered_at_hz); empty: ``RECORDING.yaml`` beside the file if there is one
role      training (identified on) | validation (unseen: predicted, never fitted)
group     recordings identified together: one training recording and any validation ones
========= ===============================================================================

A relative path is looked up in the working directory, then in the workflow's directory
(where the shipped sheets' data lie). Every row is checked against the sheet's schema
(``workflow/schemas/recordings.schema.yaml``) and every sheet as a whole (:func:`load_sheets`):
each error names the sheet, its line and column, what was found and what was expected.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from harvester.data.errors import DataError

#: Columns of a sheet, in order; ``sidecar`` may be left empty, ``notes`` is free text.
COLUMNS: tuple[str, ...] = ("recording", "file", "kind", "sidecar", "role", "group")
OPTIONAL_COLUMNS: tuple[str, ...] = ("notes",)
#: Kinds of recording and the file each takes.
KINDS: dict[str, str] = {"converted": ".csv", "raw_daq": ".csv", "emps": ".mat",
                         "public": ".mat"}
ROLES: tuple[str, ...] = ("training", "validation")
#: The chain a group runs: its recordings' kinds (all emps, or none).
GENERIC, EMPS = "generic", "emps"


@dataclass(frozen=True)
class Group:
    """A group's recordings: the training one, the validation ones (sheet order) and the
    chain it runs (``generic``: converted/raw_daq recordings; ``emps``: the EMPS study's)."""

    name: str
    training: str
    validation: tuple[str, ...]
    chain: str
    sheet: str


@dataclass(frozen=True)
class Sheet:
    """The recordings of every sheet (``table``, indexed by recording, paths resolved) and
    their groups (sheet order)."""

    table: pd.DataFrame
    groups: dict[str, Group]

    def row(self, recording: str) -> pd.Series:
        return self.table.loc[recording]

    def recordings(self, group: str | None = None, kind: str | None = None) -> list[str]:
        """Names of the recordings (of a group, of a kind), in sheet order."""
        t = self.table
        keep = pd.Series(True, index=t.index)
        if group is not None:
            keep &= t["group"] == group
        if kind is not None:
            keep &= t["kind"] == kind
        return list(t.index[keep])

    def group_of(self, recording: str) -> str:
        return str(self.table.at[recording, "group"])

    def file(self, recording: str) -> str:
        return str(self.table.at[recording, "file"])

    def sidecar(self, recording: str) -> str:
        """The recording's sidecar path, or '' for none."""
        return str(self.table.at[recording, "sidecar"])

    def raw_meta(self, recording: str) -> str:
        """The JSON beside a raw_daq recording."""
        return str(Path(self.file(recording)).with_suffix(".json"))


def resolve_path(text: str, bases: Sequence[Path]) -> Path | None:
    """``text`` as given if absolute or found in the first base (the working directory),
    else in the later bases (absolute), else None."""
    p = Path(text).expanduser()
    if p.is_absolute():
        return p if p.exists() else None
    for i, base in enumerate(bases):
        if (Path(base) / p).exists():
            return p if i == 0 else (Path(base) / p).resolve()
    return None


def _on_disk(path: Path, bases: Sequence[Path]) -> Path:
    """Where a path that :func:`resolve_path` returned lies (relative: the first base)."""
    return path if path.is_absolute() else Path(bases[0]) / path


def find_sheet(path: str | Path, bases: Sequence[Path]) -> Path:
    """The sheet file (config ``recordings``); DataError naming where it was looked for."""
    found = resolve_path(str(path), bases)
    if found is None or not _on_disk(found, bases).is_file():
        raise DataError(path, "recording sheet not found (config 'recordings'), looked in "
                        + " and ".join(str(Path(b).resolve()) for b in bases))
    return found


def read_sheet(path: str | Path) -> pd.DataFrame:
    """A sheet's rows as text (empty cells ''), with the ``line`` each comes from; DataError
    for a sheet that is not tab-separated with the columns of :data:`COLUMNS`."""
    path = Path(path)
    lines = path.read_text(encoding="utf-8-sig").splitlines()
    numbered = [(i + 1, ln) for i, ln in enumerate(lines)
                if ln.strip() and not ln.lstrip().startswith("#")]
    if not numbered:
        raise DataError(path, "empty recording sheet: expected a header "
                        + "\\t".join(COLUMNS) + " and one row per recording")
    head_line, head = numbered[0]
    header = [h.strip() for h in head.split("\t")]
    if len(header) == 1 and ("," in head or ";" in head):
        raise DataError(path, f"the header reads {head!r}: a sheet is tab-separated, not "
                        "comma- or semicolon-separated", line=head_line)
    missing = [c for c in COLUMNS if c not in header]
    unknown = [c for c in header if c not in COLUMNS + OPTIONAL_COLUMNS]
    if missing or unknown or len(set(header)) != len(header):
        what = []
        if missing:
            what.append(f"missing column(s) {missing}")
        if unknown:
            what.append(f"unknown column(s) {unknown}")
        if len(set(header)) != len(header):
            what.append("a column repeated")
        raise DataError(path, "; ".join(what) + f"; expected the columns {list(COLUMNS)} "
                        f"(optionally {list(OPTIONAL_COLUMNS)}), tab-separated",
                        line=head_line, column=(missing or unknown or [None])[0])
    rows = []
    for number, text in numbered[1:]:
        cells = [c.strip() for c in text.split("\t")]
        if len(cells) > len(header) and any(cells[len(header):]):
            raise DataError(path, f"{len(cells)} cells where the header has {len(header)} "
                            "columns (a tab too many?)", line=number)
        cells = (cells + [""] * len(header))[: len(header)]
        rows.append({**dict(zip(header, cells)), "line": number})
    if not rows:
        raise DataError(path, "no recordings: the sheet has a header and no rows")
    return pd.DataFrame(rows, columns=[*header, "line"])


def _schema_errors(row: Mapping[str, str], schema: Mapping) -> list:
    import jsonschema
    validator = jsonschema.validators.validator_for(schema)(schema)
    return sorted(validator.iter_errors(dict(row)), key=lambda e: list(e.path))


def check_rows(frame: pd.DataFrame, path: str | Path, schema: Mapping | None) -> None:
    """Each row against the schema of one row (``recordings.schema.yaml``): DataError at the
    first offending cell, with what is allowed."""
    for _, row in frame.iterrows():
        cells = {c: row[c] for c in COLUMNS + OPTIONAL_COLUMNS if c in row and row[c] != ""}
        line = int(row["line"])
        for col in ("recording", "file", "kind", "role", "group"):
            if col not in cells:
                raise DataError(path, f"empty cell: every recording needs a {col}", line=line,
                                column=col)
        if cells["kind"] not in KINDS:
            raise DataError(path, f"unknown kind {cells['kind']!r}; expected one of "
                            f"{', '.join(KINDS)}", line=line, column="kind")
        if cells["role"] not in ROLES:
            raise DataError(path, f"unknown role {cells['role']!r}; expected one of "
                            f"{', '.join(ROLES)}", line=line, column="role")
        if "sidecar" in cells and Path(cells["sidecar"]).suffix != ".yaml":
            raise DataError(path, f"a sidecar is a .yaml file, got {cells['sidecar']!r}",
                            line=line, column="sidecar")
        for err in _schema_errors(cells, schema) if schema else []:
            column = str(err.path[0]) if err.path else None
            raise DataError(path, f"{err.message} (schema: "
                            f"{err.schema.get('description', err.validator)})", line=line,
                            column=column)


def _resolved(path: Path, line: int, column: str, text: str, bases: Sequence[Path],
              what: str) -> str:
    found = resolve_path(text, bases)
    if found is None:
        raise DataError(path, f"{what} {text!r} not found (looked in "
                        + " and ".join(str(Path(b).resolve()) for b in bases) + ")",
                        line=line, column=column)
    return str(found)


def _check_files(path: Path, row: pd.Series, bases: Sequence[Path]) -> dict[str, str]:
    line, kind = int(row["line"]), row["kind"]
    suffix = KINDS[kind]
    if Path(row["file"]).suffix.lower() != suffix:
        raise DataError(path, f"a {kind} recording is a {suffix} file, got {row['file']!r}",
                        line=line, column="file")
    file = _resolved(path, line, "file", row["file"], bases, "recording")
    if kind == "raw_daq":
        meta = Path(file).with_suffix(".json")
        if not _on_disk(meta, bases).exists():
            raise DataError(path, f"a raw_daq recording needs its JSON (channels, sensitivities) "
                            f"beside it: {meta} not found", line=line, column="file")
    sidecar = row["sidecar"]
    if sidecar:
        if kind in ("emps", "public"):
            raise DataError(path, f"an {kind} recording takes no sidecar (" + (
                "the drive's constants are in the .mat file" if kind == "emps" else
                "its reader, harvester.data.public, gives what its source publishes")
                + ")", line=line, column="sidecar")
        sidecar = _resolved(path, line, "sidecar", sidecar, bases, "sidecar")
    elif kind == "converted":
        beside = Path(file).with_suffix(".yaml")
        if _on_disk(beside, bases).exists():
            sidecar = str(beside)
    return {"file": file, "sidecar": sidecar}


def _groups(table: pd.DataFrame) -> dict[str, Group]:
    groups = {}
    for name, rows in table.groupby("group", sort=False):
        sheet, first = str(rows["sheet"].iloc[0]), int(rows["line"].iloc[0])
        if rows["sheet"].nunique() > 1:
            raise DataError(sheet, f"group {name!r} also appears in "
                            f"{sorted(set(rows['sheet']) - {sheet})}: a group lies in one "
                            "sheet", line=first, column="group")
        training = list(rows.index[rows["role"] == "training"])
        validation = tuple(rows.index[rows["role"] == "validation"])
        if not training:
            raise DataError(sheet, f"group {name!r} has no training recording (its rows: "
                            f"{', '.join(rows.index)}); give one row the role training",
                            line=first, column="role")
        if len(training) > 1:
            raise DataError(sheet, f"group {name!r} has {len(training)} training recordings "
                            f"({', '.join(training)}); a group is identified on one recording "
                            "(joint identification of several is not supported): give each "
                            "its own group, or make the others validation recordings",
                            line=int(rows.at[training[1], "line"]), column="role")
        kinds = set(rows["kind"])
        if "emps" in kinds and kinds != {"emps"}:
            others = sorted(kinds - {"emps"})
            raise DataError(sheet, f"group {name!r} mixes EMPS recordings with {others}: an "
                            "EMPS group runs the EMPS study's chain, its recordings are all "
                            "emps", line=first, column="kind")
        chain = EMPS if kinds == {"emps"} else GENERIC
        if chain == EMPS and len(validation) != 1:
            raise DataError(sheet, f"EMPS group {name!r} has {len(validation)} validation "
                            "recordings; the EMPS study validates on exactly one",
                            line=first, column="role")
        groups[str(name)] = Group(str(name), training[0], validation, chain, sheet)
    emps = [g.name for g in groups.values() if g.chain == EMPS]
    if len(emps) > 1:
        g = groups[emps[1]]
        raise DataError(g.sheet, f"{len(emps)} EMPS groups ({', '.join(emps)}); the EMPS "
                        "study's rules (workflow/rules/emps.smk) take one",
                        line=int(table.at[g.training, "line"]), column="group")
    return groups


def load_sheets(paths: str | Iterable[str], schema: Mapping | None = None,
                bases: Sequence[str | Path] = (".",), reserved: Iterable[str] = ()) -> Sheet:
    """Read, check and combine the sheets named by config ``recordings`` (one path or a list).

    ``schema``: the JSON schema of one row; ``bases``: where relative paths are looked up,
    the working directory first; ``reserved``: recording names the workflow keeps for itself
    (the virtual rig's loaded records). DataError (sheet, line, column) for a malformed sheet,
    an unknown kind or role, a missing recording, JSON or sidecar, a duplicate name, a group
    without its training recording (or with several), or more than one EMPS group.
    """
    bases = [Path(b) for b in bases]
    frames = []
    for given in ([paths] if isinstance(paths, str) else list(paths)):
        path = find_sheet(given, bases)
        frame = read_sheet(_on_disk(path, bases))
        check_rows(frame, path, schema)
        files = [_check_files(path, row, bases) for _, row in frame.iterrows()]
        frame["file"] = [f["file"] for f in files]
        frame["sidecar"] = [f["sidecar"] for f in files]
        frame["sheet"] = str(path)
        frames.append(frame)
    if not frames:
        raise DataError("<config>", "'recordings' names no sheet")
    table = pd.concat(frames, ignore_index=True)
    if "notes" not in table:
        table["notes"] = ""
    reserved = set(reserved)
    seen: dict[str, tuple[str, int]] = {}
    for _, row in table.iterrows():
        name, where = row["recording"], (row["sheet"], int(row["line"]))
        if name in seen:
            raise DataError(where[0], f"recording {name!r} is named twice (also {seen[name][0]}, "
                            f"line {seen[name][1]}): names must be unique", line=where[1],
                            column="recording")
        if name in reserved:
            raise DataError(where[0], f"recording name {name!r} is kept for the virtual rig's "
                            "records of the same name: choose another", line=where[1],
                            column="recording")
        seen[name] = where
    table = table.set_index("recording", drop=False)
    table.index.name = None
    return Sheet(table, _groups(table))


def recording_header(path: str | Path) -> list[str]:
    """The column names on a CSV's first line (for decisions at start-up)."""
    with open(path, encoding="utf-8-sig") as fh:
        return [c.strip() for c in fh.readline().split(",")]
