"""What the diagnosis can name: the model graph (:mod:`.graph`), the
physical domains (:mod:`.domain`), the hypotheses (:mod:`.hypotheses`,
with the small elements they insert, :mod:`.elements`), the generic
located term (:mod:`.generic`), and how a library is loaded
(:mod:`.loader`)."""
