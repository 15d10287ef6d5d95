"""What a diagnosis shows: the result and its JSON views (:mod:`.result`),
``report.md`` (:mod:`.markdown`) and its plots (:mod:`.plots`). Pure views:
nothing here simulates."""
