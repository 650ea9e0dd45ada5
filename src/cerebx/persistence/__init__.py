"""Writing a running loop's state to disk and reading it back: the checkpoint store (a run's arrays file, the
journal of changed rows, the pickle of the rest, written beside the running loop). When a run resumes from it
and which runs may be reused is the loop's decision (``loop/resume.py``)."""
