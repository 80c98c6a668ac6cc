"""The methods: ``registry`` (method name -> class, by ``module:Class``), ``albot1`` (the
Albot1 mapper of thesis chapter 3) and ``baselines`` (odometry, KISS-ICP, the GTSAM pose
graph). Every method implements :class:`albot1.contract.Mapper`."""
