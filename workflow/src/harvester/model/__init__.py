"""The physics: named terms, model structures and the compiled simulator."""
