from poinsot.app.cli.main import main

raise SystemExit(main())
