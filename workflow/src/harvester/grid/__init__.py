"""The concealed-effect grid: scenarios diagnosed, scored and tabulated."""
