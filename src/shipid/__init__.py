"""shipid: semiphysical identification of ship manoeuvring models with LS-SVM."""
__version__ = "0.1.0"
