"""Model files, tables, figures and reports."""
