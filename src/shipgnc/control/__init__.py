"""Controllers: discrete, explicit, batched (``reset(batch_shape)`` / ``step(t, y, ref)``)."""
