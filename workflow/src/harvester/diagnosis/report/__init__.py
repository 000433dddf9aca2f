"""Stage 5, report: the fit on unseen data, diagnosis.json and the pages a user reads.

``document``       diagnosis.json as a dictionary (its ``SCHEMA_VERSION``; the schema is
                   ``diagnosis.schema.json`` beside it, docs/diagnosis-json.md key by key),
                   and the fit on unseen data of one posterior (``UnseenFit``)
``unseen``         the baseline and the improved model on unseen data, and the judgement of
                   the fit against the noise floor
``thresholds``     every threshold that shaped the verdict, as diagnosis.json records it
``figures``        the diagnosis's figures (where, which effects, the fit before and after)
``summary_page``   the diagnosis as one self-contained page (summary.html)
"""
