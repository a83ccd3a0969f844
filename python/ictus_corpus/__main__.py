import sys

from ictus_corpus.run import main

sys.exit(main())
