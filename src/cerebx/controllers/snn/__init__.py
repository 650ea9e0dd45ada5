"""The cerebellar spiking controller: its schema (``schema.py``) beside its code (``controller.py``)."""
