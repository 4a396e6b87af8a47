import sys

from bcfem.cli import main

sys.exit(main())
