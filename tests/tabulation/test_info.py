"""`tablegen info`'s summary of a table (tablegen.tabulation.info.describe_table) stays a table whatever its shapes'
names: each column as wide as its longest entry."""

import dataclasses

from data_schema.table import read_table
from tablegen.tabulation.info import describe_table

LONG = "sand_crushed_" + "x" * 51      # 64 characters, the longest name a shape may have

def test_a_long_shape_name_keeps_its_own_column(grain_table_path):
    table = read_table(grain_table_path)
    records = tuple(dataclasses.replace(r, name=LONG[:-1] + str(i)) for i, r in enumerate(table.shape_records()))
    renamed = dataclasses.replace(table, shapes=tuple(r.name for r in records), records=records)
    lines = describe_table(renamed).splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("shape "))
    rows = lines[head + 1:]
    assert [row.split()[0] for row in rows] == list(renamed.shapes)
    # the name column as wide as the longest name, then two spaces; every row as long, the entries right-aligned
    width = max(map(len, renamed.shapes))
    for row, name in zip(rows, renamed.shapes):
        assert row[:width].rstrip() == name and row[width:width + 2] == "  ", row
    assert len({len(row) for row in [lines[head]] + rows}) == 1
    assert all(row.endswith(")") for row in rows) and lines[head].endswith("failed %")
    shape_lines = [line for line in lines if line.startswith("  " + LONG[:-1])]
    assert len(shape_lines) == len(records) and all(line.split()[1] == "user" for line in shape_lines)
