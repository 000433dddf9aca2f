"""The paper's study: its numbers, its data set, its tables and headline."""
