"""`python -m kitsuke.batch._worker FD`: a LocalRunner worker, talking to its driver over the socket FD."""

import sys

from kitsuke.batch.local import local_worker

if __name__ == "__main__":
    local_worker(int(sys.argv[1]))
