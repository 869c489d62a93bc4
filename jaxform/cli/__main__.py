import sys

from jaxform.cli import main

sys.exit(main())
